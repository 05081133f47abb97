"""Modal response-spectrum analysis (pounding.studies.design) against a response-history run."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from pounding.model.model import load_model, model_from_text
from pounding.records.design_spectra import asce7_22_spectrum, tabulated_spectrum
from pounding.records.load import load_record
from pounding.records.spectra import response_spectrum
from pounding.simulation import simulate
from pounding.studies.design import cqc_combine, modal_response
from pounding.units import STANDARD_GRAVITY

ROOT = Path(__file__).resolve().parents[1]
RECORD = ROOT / "ground_motions" / "peer" / "NIS090.AT2"
DURATION = 8.0


def test_sdof_rsa_with_the_records_own_spectrum_equals_the_response_history_peak():
    # One storey, m = 1e5 kg, k = 4e7 N/m: T = 2 pi sqrt(m/k) = 0.31416 s, 5 % modal damping.
    text = f"""
name: sdof
buildings:
  - name: S
    storeys: [{{mass: 1.0e5, stiffness: 4.0e7, height: 3.0}}]
    damping: {{modal: [0.05]}}
ground_motion: {{record: {RECORD}, duration: {DURATION}}}
solver: {{rtol: 1.0e-10, atol: 1.0e-12, atol_velocity: 1.0e-11}}
"""
    model = model_from_text(text)
    building = model.buildings[0]
    period = float(building.periods[0])
    assert period == pytest.approx(2 * np.pi * np.sqrt(1e5 / 4e7))
    peak = float(simulate(model).peak_displacement.values[0])
    # The record's own 5 % spectrum at T over the same 8 s (the exact piecewise-linear method),
    # given as a user spectrum in g.
    record = load_record(str(RECORD))
    samples = int(round(DURATION / record.time_step)) + 1
    sa = float(response_spectrum(record.acceleration[:samples], record.time_step, [period], 0.05).psa[0])
    user = tabulated_spectrum([0.5 * period, period, 2 * period], [0.0, sa / STANDARD_GRAVITY, 0.0])
    rsa = modal_response(building, user)
    assert rsa.n_modes == 1 and rsa.mass_fraction == pytest.approx(1.0)
    # Measured 1.1e-9 relative at rtol 1e-10 (7.4e-7 at the default rtol 1e-6).
    assert rsa.displacement[0] == pytest.approx(peak, rel=1e-6)


def test_enough_modes_for_90_percent_of_the_mass():
    building = load_model(ROOT / "models" / "pair.yaml").buildings[0]     # A: 8 uniform storeys
    rsa = modal_response(building, asce7_22_spectrum(1.0, 0.6, 8.0))
    omega, phi = building.modes
    ratios = (phi.T @ building.mass) ** 2 / building.mass.sum()
    assert rsa.mass_fraction >= 0.9 > ratios[:rsa.n_modes - 1].sum()
    assert rsa.n_modes == 2                                            # 0.856 after mode 1, 0.947 after mode 2
    assert rsa.displacement[-1] > rsa.displacement[0] > 0


def test_cqc_limits():
    modal = np.array([[0.03, 0.06], [0.04, -0.02]])
    # equal periods and damping: rho = 1, the algebraic sum |r1 + r2|
    assert cqc_combine(modal, [1.0, 1.0], [0.05, 0.05]) == pytest.approx(np.abs(modal.sum(axis=0)))
    # far-apart periods: rho -> 0, SRSS
    assert cqc_combine(modal, [1.0, 0.01], [0.05, 0.05]) == pytest.approx(np.hypot(*modal), rel=1e-3)
