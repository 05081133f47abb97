"""Run the default building pair, archive it, and look at the results with xarray.

    python examples/run_pair.py
"""

import pounding
from pounding.results.plots import plot_run

model = pounding.load_model("models/pair.yaml")
print({name: periods[:3].round(3) for name, periods in model.periods.items()})

ds = pounding.simulate(model)                      # the model's own record (FEMA P695 far-field 1a)
print(ds.peak_drift_ratio.to_series().mul(100).round(3))    # % per storey
print(ds[["impact_time", "impact_velocity", "impact_peak_force"]].to_dataframe().head())

pounding.save_run(ds, "pair_example.nc", overwrite=True)   # atomic NetCDF write
again = pounding.open_run("pair_example.nc")
print(again.displacement.sel(floor="A:5").max().item(), "m peak roof-level displacement of A's 5th floor")
plot_run(again, "pair_example_plots")
