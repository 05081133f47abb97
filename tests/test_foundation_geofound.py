"""The footing springs against a second implementation: geofound (eng-tools), written from the same papers.

geofound implements Gazetas (1991) and Pais & Kausel (1988) (with NIST GCR 12-917-21's Table 2-3a dynamic
modifiers for the latter) in code that shares nothing with :mod:`pounding.model.foundation_impedance`.  Where the
two follow the same formula they agree to round-off; where they do not, the difference is stated and tested as
what it is (docs/foundations-soil.md, "Checked against geofound"):

* the static surface stiffnesses of both fits, sway and rocking, both orientations of the footing: equal;
* Pais & Kausel's dynamic rocking modifier α_yy(a0) at the surface: equal;
* Pais & Kausel's embedded rocking: geofound multiplies the static stiffness by the embedment factor η twice
  (``k_f_0_static * f_r_dyn * n_emb`` with ``k_f_0_static`` already holding ``n_emb``), so its value over ours
  is exactly η;
* Gazetas' dynamic rocking: geofound takes Gazetas' own modifier (1 − 0.2 a0 about the long axis, 1 − 0.3 a0
  about the short one), this package NIST's Table 2-3a α for both fits.
"""

from __future__ import annotations

import pytest
import sfsimodels   # geofound's soil and foundation objects (installed with it: the test extra)
from geofound.stiffness import gazetas_1991 as gazetas
from geofound.stiffness import pais_1988 as pais

from pounding.model.foundation_impedance import Footing, Soil, impedances

#: Both implementations evaluate the same closed forms in double precision: a few ulps.
ROUND_OFF = 1e-12
#: Footings (length along the shaking, width, Poisson's ratio): long and short sides along x, a square, a strip-like one.
FOOTINGS = [(30.0, 20.0, 0.33), (20.0, 30.0, 0.25), (16.0, 16.0, 0.40), (40.0, 10.0, 0.30)]


def _theirs(length: float, width: float, nu: float, soil: Soil, depth: float = 0.0):
    sl = sfsimodels.Soil()
    sl.g_mod, sl.poissons_ratio, sl.unit_dry_weight = soil.shear_modulus, nu, soil.density * 9.81
    fd = sfsimodels.RaftFoundation()
    fd.length, fd.width, fd.depth, fd.height, fd.mass = length, width, depth, max(depth, 1.0), 0.0
    return sl, fd


@pytest.mark.parametrize("length, width, nu", FOOTINGS)
def test_static_surface_springs_equal_geofounds(length, width, nu):
    soil = Soil(200.0, nu, 1900.0)
    sl, fd = _theirs(length, width, nu, soil)
    ours = {m: impedances(soil, Footing(length, width), 0.0, m) for m in ("gazetas", "pais-kausel")}
    # shaking along x = along the footing's `length`: geofound's in-plane axis "length"
    pairs = [(ours["gazetas"].sway_x.static, gazetas.calc_horz_via_gazetas_1991(sl, fd, ip_axis="length")),
             (ours["gazetas"].rocking_y.static, gazetas.calc_rot_via_gazetas_1991(sl, fd, ip_axis="length")),
             (ours["pais-kausel"].sway_x.static, pais.calc_horz_via_pais_1988(sl, fd, ip_axis="length")),
             (ours["pais-kausel"].rocking_y.static, pais.calc_rot_via_pais_1988(sl, fd, ip_axis="length"))]
    for mine, other in pairs:
        assert mine == pytest.approx(other, rel=ROUND_OFF)


@pytest.mark.parametrize("omega", [4.0, 8.0, 15.0])
def test_pais_kausels_dynamic_rocking_at_the_surface_equals_geofounds(omega):
    soil = Soil(150.0, 0.33, 1900.0)
    sl, fd = _theirs(30.0, 20.0, 0.33, soil)
    ours = impedances(soil, Footing(30.0, 20.0), omega, "pais-kausel")
    assert ours.rocking_y.alpha < 1.0        # the modifier does act at these frequencies
    other = pais.calc_rot_via_pais_1988(sl, fd, ip_axis="length", a0=ours.a0)
    assert ours.rocking_y.stiffness == pytest.approx(other, rel=ROUND_OFF)


def test_geofound_applies_pais_kausels_rocking_embedment_twice():
    soil = Soil(200.0, 0.33, 1900.0)
    sl, fd = _theirs(30.0, 20.0, 0.33, soil, depth=3.0)
    ours = impedances(soil, Footing(30.0, 20.0, 3.0), 0.0, "pais-kausel")
    other = pais.calc_rot_via_pais_1988(sl, fd, ip_axis="length")
    eta = ours.rocking_y.embedment_factor
    assert eta > 1.2                          # 3 m of a 20 m footing: a real embedment
    assert other == pytest.approx(ours.rocking_y.stiffness * eta, rel=ROUND_OFF)
