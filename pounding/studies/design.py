"""Design displacements by modal response-spectrum analysis, and the codes' separation rules.

Modal response-spectrum analysis (each building on its own)
------------------------------------------------------------
For a shear building with mass-normalised modes φ_k (``φᵀMφ = I``), circular
frequencies ω_k and participation factors Γ_k = φ_kᵀ M 1, the peak floor
displacements of mode k under a spectrum Sa(T) (g) are::

    u_k = Γ_k φ_k Sa(T_k) g / ω_k²

and the modes are combined by the complete quadratic combination (CQC)::

    u = √( Σ_i Σ_j ρ_ij u_i u_j )

with ρ_ij the coefficient of Der Kiureghian (1981) —
:func:`pounding.studies.gap.cqc_correlation`, the one the gap study uses for
the DDC rule — at the modes' own damping ratios (the building's Rayleigh or
modal damping).  The modes used are the fewest, from the first, whose
effective masses Γ_k² reach 90 % of the building's mass (ASCE 7-22 §12.9.1.1;
EN 1998-1 §4.3.3.3.1(3)); all modes if the building has fewer.  The codes'
spectra are at 5 % damping; the CQC coefficients use the building's damping
(5 % for the codes' usual models), so a building damped otherwise mixes the
two — this is said, not corrected.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import numpy as np

from pounding.studies.gap import cqc_correlation
from pounding.units import STANDARD_GRAVITY

__all__ = ["ModalResponse", "modal_response", "cqc_combine", "MASS_FRACTION"]

#: Participating mass the modes of a response-spectrum analysis must reach (ASCE 7-22 §12.9.1.1, EC8 §4.3.3.3.1).
MASS_FRACTION = 0.90


@dataclass(frozen=True, eq=False)
class ModalResponse:
    """The response-spectrum analysis of one building.

    Attributes
    ----------
    building : str
        Building name.
    periods, damping : (m,) ndarray
        Periods (s) and damping ratios of the m modes used.
    participation : (m,) ndarray
        Participation factors Γ_k = φ_kᵀ M 1 of the mass-normalised modes, kg^½.
    mass_ratio : (m,) ndarray
        Effective modal mass Γ_k² over the building's mass.
    sa : (m,) ndarray
        Spectral acceleration at each mode's period, g.
    modal_displacement : (m, n) ndarray
        Peak floor displacements of each mode, m, signed (Γ_k φ_k Sd_k).
    displacement : (n,) ndarray
        CQC combination of the modes: peak floor displacements, m, floor 1 first.
    """

    building: str
    periods: np.ndarray
    damping: np.ndarray
    participation: np.ndarray
    mass_ratio: np.ndarray
    sa: np.ndarray
    modal_displacement: np.ndarray
    displacement: np.ndarray

    @property
    def n_modes(self) -> int:
        """Number of modes used."""
        return int(self.periods.size)

    @property
    def mass_fraction(self) -> float:
        """Participating mass of the modes used, as a fraction of the building's mass."""
        return float(self.mass_ratio.sum())


def cqc_combine(modal: Any, periods: Any, damping: Any) -> np.ndarray:
    """CQC combination √(Σ_i Σ_j ρ_ij r_i r_j) of modal peak responses *modal* (m, n) along the modes.

    Parameters
    ----------
    modal : (m, n) array
        Signed peak response of each mode (rows) at n places.
    periods, damping : (m,) array
        The modes' periods (s) and damping ratios; ρ_ij by :func:`pounding.studies.gap.cqc_correlation`.

    Returns
    -------
    (n,) ndarray
        The combined peak responses (≥ 0).
    """
    r = np.atleast_2d(np.asarray(modal, dtype=float))
    t = np.asarray(periods, dtype=float)
    z = np.asarray(damping, dtype=float)
    rho = np.array([[cqc_correlation(t[i], t[j], z[i], z[j]) for j in range(t.size)] for i in range(t.size)])
    return np.sqrt(np.maximum(np.einsum("in,ij,jn->n", r, rho, r), 0.0))


def modal_response(building, spectrum, *, mass_fraction: float = MASS_FRACTION) -> ModalResponse:
    """Peak floor displacements of *building* on its own under *spectrum*, by modes and CQC.

    Parameters
    ----------
    building : pounding.model.Building
        A shear building (its elastic storey stiffnesses; yielding is not modelled here).
    spectrum : DesignSpectrum
        Anything with ``sa(periods) -> Sa in g`` (:mod:`pounding.records.design_spectra`).
    mass_fraction : float
        Participating mass the modes must reach (default 90 %).

    Returns
    -------
    ModalResponse
    """
    omega, phi = building.modes
    mass = np.asarray(building.mass, dtype=float)
    gamma_all = phi.T @ mass
    ratio_all = gamma_all ** 2 / mass.sum()
    needed = int(np.searchsorted(np.cumsum(ratio_all), mass_fraction - 1e-12) + 1)
    m = min(max(needed, 1), omega.size)
    w = np.asarray(omega[:m])
    periods = 2.0 * np.pi / w
    sa = spectrum.sa(periods)
    sd = sa * STANDARD_GRAVITY / w ** 2
    modal = (gamma_all[:m] * sd)[:, None] * np.asarray(phi[:, :m]).T
    damping = np.asarray(building.modal_damping_ratios[:m], dtype=float)
    return ModalResponse(building=building.name, periods=periods, damping=damping, participation=gamma_all[:m],
                         mass_ratio=ratio_all[:m], sa=np.asarray(sa, dtype=float), modal_displacement=modal,
                         displacement=cqc_combine(modal, periods, damping))
