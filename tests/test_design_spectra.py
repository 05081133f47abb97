"""Design spectra of ASCE 7-22, Eurocode 8 and a user table, against values worked out by hand below."""

from __future__ import annotations

import math

import numpy as np
import pytest

from pounding.cli import main
from pounding.errors import PoundingError
from pounding.records.design_spectra import (asce7_22_spectrum, asce7_22_two_period, ec8_damping_correction,
                                             ec8_ground_parameters, ec8_spectrum, read_user_spectrum,
                                             tabulated_spectrum)


def test_asce7_22_two_period_by_hand():
    # S_DS = 1.0 g, S_D1 = 0.6 g, T_L = 8 s: T0 = 0.2 * 0.6 / 1.0 = 0.12 s, Ts = 0.6 / 1.0 = 0.6 s.
    #   T = 0     : S_DS * 0.4                        = 0.4
    #   T = 0.06  : S_DS * (0.4 + 0.6 * 0.06 / 0.12)  = 0.7
    #   T = 0.3   : plateau S_DS                      = 1.0
    #   T = 0.6   : Ts, still S_DS                    = 1.0
    #   T = 1.0   : S_D1 / T = 0.6 / 1                = 0.6
    #   T = 2.0   : 0.6 / 2                           = 0.3
    #   T = 8.0   : T_L, 0.6 / 8                      = 0.075
    #   T = 10    : S_D1 T_L / T^2 = 0.6 * 8 / 100    = 0.048
    t = [0.0, 0.06, 0.3, 0.6, 1.0, 2.0, 8.0, 10.0]
    expected = [0.4, 0.7, 1.0, 1.0, 0.6, 0.3, 0.075, 0.048]
    assert asce7_22_two_period(t, 1.0, 0.6, 8.0) == pytest.approx(expected, rel=1e-12)
    design = asce7_22_spectrum(1.0, 0.6, 8.0)
    assert design.sa(t) == pytest.approx(expected, rel=1e-12)
    # MCE_R: 1.5 x design (S_MS = 1.5 S_DS): at T = 2 s, 1.5 * 0.3 = 0.45 g.
    mce = asce7_22_spectrum(1.0, 0.6, 8.0, mce=True)
    assert mce.sa([2.0])[0] == pytest.approx(0.45, rel=1e-12)
    assert "MCE_R" in mce.name and "§11.4.6" in mce.clause
    assert design.corners == pytest.approx((0.12, 0.6, 8.0))


def test_ec8_tables_and_eta():
    assert ec8_ground_parameters(1, "B") == (1.2, 0.15, 0.5, 2.0)        # Table 3.2
    assert ec8_ground_parameters(2, "d") == (1.8, 0.10, 0.30, 1.2)       # Table 3.3
    # eta = sqrt(10 / (5 + xi)), xi in %: 5 % -> 1; 10 % -> sqrt(10/15) = 0.81650; 30 % -> 0.5345 < 0.55 -> 0.55
    assert ec8_damping_correction(0.05) == pytest.approx(1.0)
    assert ec8_damping_correction(0.10) == pytest.approx(math.sqrt(10 / 15))
    assert ec8_damping_correction(0.30) == 0.55


def test_ec8_elastic_by_hand():
    # Type 1, ground B: S = 1.2, T_B = 0.15, T_C = 0.5, T_D = 2.0 s; a_g = 0.3 g, 5 % (eta = 1).
    #   T = 0   : a_g S                          = 0.36
    #   T = 0.3 : a_g S 2.5          = 0.3*1.2*2.5 = 0.9
    #   T = 1.0 : 0.9 * T_C / T     = 0.9 * 0.5   = 0.45
    #   T = 3.0 : 0.9 * T_C T_D / T^2 = 0.9 * 1 / 9 = 0.1
    spectrum = ec8_spectrum(1, "B", 0.3)
    assert spectrum.sa([0.0, 0.3, 1.0, 3.0]) == pytest.approx([0.36, 0.9, 0.45, 0.1], rel=1e-12)
    # 10 % damping: the plateau 0.9 * sqrt(10/15) = 0.734847
    assert ec8_spectrum(1, "B", 0.3, damping=0.10).sa([0.3])[0] == pytest.approx(0.9 * math.sqrt(10 / 15))


def test_ec8_design_by_hand():
    # Design spectrum (§3.2.2.5), type 1, ground B, a_g = 0.3 g, q = 3.9, beta = 0.2:
    #   T = 0     : a_g S 2/3                        = 0.36 * 2/3           = 0.24
    #   T = 0.075 : a_g S [2/3 + 0.5 (2.5/3.9 - 2/3)] = 0.36 * 0.6538462    = 0.2353846
    #   T = 0.3   : a_g S 2.5 / q = 0.9 / 3.9                              = 0.2307692
    #   T = 1.0   : 0.2307692 * 0.5                                        = 0.1153846
    #   T = 3.0   : 0.2307692 * 0.5 * 2 / 9 = 0.025641 < beta a_g = 0.06    -> 0.06
    spectrum = ec8_spectrum(1, "B", 0.3, q=3.9)
    expected = [0.24, 0.36 * (2 / 3 + 0.5 * (2.5 / 3.9 - 2 / 3)), 0.9 / 3.9, 0.45 / 3.9, 0.06]
    assert spectrum.sa([0.0, 0.075, 0.3, 1.0, 3.0]) == pytest.approx(expected, rel=1e-12)
    assert expected[1] == pytest.approx(0.2353846, abs=1e-7)
    with pytest.raises(PoundingError, match="no damping correction"):
        ec8_spectrum(1, "B", 0.3, q=3.9, damping=0.1)


def test_user_spectrum_file(tmp_path):
    path = tmp_path / "usgs.txt"
    path.write_text("# multi-period spectrum, ASCE 7-22 §11.4.5.1\n0.0 0.4\n0.2, 1.0\n\n1.0\t0.5\n", encoding="utf-8")
    spectrum = read_user_spectrum(path)
    # linear in T: at 0.1 s halfway between 0.4 and 1.0 -> 0.7; at 0.6 s halfway between 1.0 and 0.5 -> 0.75
    assert spectrum.sa([0.1, 0.6, 1.0]) == pytest.approx([0.7, 0.75, 0.5])
    with pytest.raises(PoundingError, match="outside the spectrum"):
        spectrum.sa([1.5])


@pytest.mark.parametrize("text, message", [
    ("0.1\n", ":1: expected two columns"),
    ("0.1 0.2\n0.1 0.3\n", ":2: periods must increase"),
    ("0.1 0.2\n0.2 -1\n", ":2: period and Sa must be finite and >= 0"),
    ("0.1 0.2\n", "needs at least two rows"),
    ("0.1 a\n", ":1: not a number"),
])
def test_bad_user_files_are_one_line(tmp_path, text, message):
    path = tmp_path / "bad.txt"
    path.write_text(text, encoding="utf-8")
    with pytest.raises(PoundingError, match=message) as caught:
        read_user_spectrum(path)
    assert "\n" not in str(caught.value)
    with pytest.raises(PoundingError, match="file not found"):
        read_user_spectrum(tmp_path / "missing.txt")


def test_tabulated_refuses_periods_outside_the_table(tmp_path, capsys):
    spectrum = tabulated_spectrum([0.5, 1.0], [1.0, 0.5])
    with pytest.raises(PoundingError, match=r"period 0.2 s is outside the spectrum \(0.5 to 1 s\)"):
        spectrum.sa([0.2])
    # the command's table starts at the table's first period
    path = tmp_path / "late.txt"
    path.write_text("0.5 1.0\n1.0 0.5\n", encoding="utf-8")
    assert main(["spectrum", "user", str(path)]) == 0
    rows = [line.split() for line in capsys.readouterr().out.splitlines()[3:]]
    assert [float(r[0]) for r in rows] == pytest.approx([0.5, 0.6, 0.7, 0.8, 0.9, 1.0])
    assert float(rows[-1][1]) == pytest.approx(0.5)


def test_cli_prints_plots_and_writes_csv(tmp_path, capsys):
    png, table = tmp_path / "figs" / "asce.png", tmp_path / "asce.csv"
    assert main(["spectrum", "asce7-22", "--sds", "1.0", "--sd1", "0.6", "--tl", "8", "--mce",
                 "--plot", str(png), "--csv", str(table)]) == 0
    out = capsys.readouterr().out
    assert "ASCE 7-22 MCE_R" in out and png.exists()
    rows = np.loadtxt(table, delimiter=",", skiprows=1)
    at_one = rows[np.isclose(rows[:, 0], 1.0)][0]
    assert at_one[1] == pytest.approx(0.9)                       # 1.5 * 0.6 / 1
    assert at_one[2] == pytest.approx(0.9 * 9.80665 / (4 * math.pi ** 2))   # Sd = Sa g / omega^2
    assert main(["spectrum", "ec8", "--type", "1", "--ground", "B", "--ag", "0.3", "--q", "3.9"]) == 0
    assert "0.2308" in capsys.readouterr().out                   # the plateau 0.9 / 3.9
    assert main(["spectrum", "ec8", "--ground", "F", "--ag", "0.3"]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "ground type" in err
