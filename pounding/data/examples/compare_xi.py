"""Compare xi formulas on storey drifts for the default pair, one record.

    python examples/compare_xi.py
"""

import pandas as pd

import pounding

model = pounding.load_model("models/pair.yaml")
formulas = ["exact", "ye", "lankarani-nikravesh", "hunt-crossley"]
drifts = {}
for name in formulas:
    ds = pounding.simulate(model, xi=name)
    drifts[name] = ds.peak_drift_ratio.to_series() * 100
    print(f"{name:22s} impacts {int(ds.impact_count.sum()):3d}  "
          f"dissipated by contacts {ds.energy_contact_dissipated[-1].item() / 1e3:8.1f} kJ")
table = pd.DataFrame(drifts)
table["ye - exact"] = table["ye"] - table["exact"]
print(table.round(4))
