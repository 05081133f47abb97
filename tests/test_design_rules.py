"""The codes' separation rules (pounding.studies.design), each against a hand calculation written out here."""

from __future__ import annotations

import math

import pytest

from pounding.studies.design import (asce7_22_displacements, asce7_22_inelastic_displacement, asce7_22_separation,
                                     ec8_design_displacement, ec8_separation, is1893_separation,
                                     nzs1170_5_separation, ntc2004_separation, ntc2004_setback)


def test_asce7_22_by_hand():
    # Building 1: elastic RSA displacement of the design spectrum u = 60 mm, R = 8, C_d = 5.5, I_e = 1.0
    #   delta_max = u I_e / R = 0.060 * 1.0 / 8      = 0.0075 m
    #   delta_M1  = C_d delta_max / I_e = 5.5 * 0.0075 = 0.04125 m
    # Building 2: u = 20 mm, R = 2, C_d = 1.75, I_e = 1.25
    #   delta_max = 0.020 * 1.25 / 2                  = 0.0125 m
    #   delta_M2  = 1.75 * 0.0125 / 1.25              = 0.0175 m
    # One property: delta_MT = sqrt(0.04125^2 + 0.0175^2) = sqrt(0.0017015625 + 0.00030625)
    #                        = sqrt(0.0020078125)                                = 0.0448086 m
    # Property line: each set back by its delta_M: 0.04125 + 0.0175 = 0.05875 m between them.
    assert asce7_22_inelastic_displacement(0.0075, 5.5, 1.0) == pytest.approx(0.04125)
    d1 = float(asce7_22_displacements([0.060], 8.0, 5.5, 1.0)[0])
    d2 = float(asce7_22_displacements([0.020], 2.0, 1.75, 1.25)[0])
    assert (d1, d2) == pytest.approx((0.04125, 0.0175))
    sep = asce7_22_separation(d1, d2)
    assert sep.same_property == pytest.approx(math.sqrt(0.0020078125)) == pytest.approx(0.0448086, abs=1e-7)
    assert (sep.setback_left, sep.setback_right, sep.property_lines) == pytest.approx((0.04125, 0.0175, 0.05875))


def test_ec8_by_hand():
    # d_e1 = 20 mm with q = 3.9: d_s1 = q d_e = 0.078 m; d_e2 = 10 mm with q = 1.5: d_s2 = 0.015 m
    # One property (4.4.2.7(2)b): sqrt(0.078^2 + 0.015^2) = sqrt(0.006084 + 0.000225) = sqrt(0.006309) = 0.0794292 m
    # Floor levels coincide (4.4.2.7(3)): 0.7 * 0.0794292 = 0.0556004 m; setbacks 0.7 * 0.078, 0.7 * 0.015
    ds1 = float(ec8_design_displacement(0.020, 3.9))
    ds2 = float(ec8_design_displacement(0.010, 1.5))
    assert (ds1, ds2) == pytest.approx((0.078, 0.015))
    apart = ec8_separation(ds1, ds2, same_levels=False)
    assert apart.same_property == pytest.approx(0.0794292, abs=1e-7)
    assert apart.property_lines == pytest.approx(0.093)
    level = ec8_separation(ds1, ds2, same_levels=True)
    assert level.same_property == pytest.approx(0.0556004, abs=1e-7)
    assert (level.setback_left, level.setback_right) == pytest.approx((0.0546, 0.0105))


def test_is1893_by_hand():
    # Delta_1 = 10 mm with R = 5, Delta_2 = 4 mm with R = 3: 5 * 0.010 + 3 * 0.004 = 0.050 + 0.012 = 0.062 m;
    # floor levels at the same elevation: R -> R/2, 0.031 m.  No property-line rule.
    assert is1893_separation(0.010, 0.004, 5.0, 3.0, same_levels=False).same_property == pytest.approx(0.062)
    level = is1893_separation(0.010, 0.004, 5.0, 3.0, same_levels=True)
    assert level.same_property == pytest.approx(0.031)
    assert math.isnan(level.property_lines)


def test_nzs1170_5_by_hand():
    # ULS deflections 50 mm and 120 mm: sqrt(0.05^2 + 0.12^2) = 0.13 m on one site; 0.05 + 0.12 = 0.17 m at boundaries.
    sep = nzs1170_5_separation(0.05, 0.12)
    assert sep.same_property == pytest.approx(0.13)
    assert sep.property_lines == pytest.approx(0.17)


def test_ntc2004_by_hand():
    # Zone II, level at h = 12 m: displacement 40 mm -> 0.040 + 0.003 * 12 = 0.076 m;
    #                              displacement 20 mm -> 0.020 + 0.036      = 0.056 m
    # Between the two: the sum 0.132 m; alike (same height and structure, slabs level): half, 0.066 m.
    s1, s2 = ntc2004_setback(0.040, 12.0, "II"), ntc2004_setback(0.020, 12.0, "ii")
    assert (s1, s2) == pytest.approx((0.076, 0.056))
    assert ntc2004_separation(s1, s2).same_property == pytest.approx(0.132)
    assert ntc2004_separation(s1, s2, alike=True).same_property == pytest.approx(0.066)
    # 10 mm at 12 m: 0.010 + 0.036 = 0.046 < 50 mm -> 0.050 m
    assert ntc2004_setback(0.010, 12.0, "II") == pytest.approx(0.050)
    # Zone I, 10 mm at 6 m: 0.010 + 0.001 * 6 = 0.016 < 50 mm -> 0.050 m
    assert ntc2004_setback(0.010, 6.0, "I") == pytest.approx(0.050)
    # Simplified method, zone III, 10 m: max(0.050, 0.012 * 10) = 0.12 m
    assert ntc2004_setback(0.0, 10.0, "III", simplified=True) == pytest.approx(0.12)
    with pytest.raises(ValueError, match="zone"):
        ntc2004_setback(0.01, 3.0, "IV")
