"""Monte Carlo and grid campaigns over any scenario parameter, run on Dask, results in a Parquet dataset.

    from freefloat import campaign
    spec = campaign.load_spec("zhang2020_velocity_sweep")      # built-in name or YAML file
    res = campaign.run_campaign(spec, "out/", runs=4, workers=2)  # LocalCluster; scheduler="tcp://..." for a cluster
    table = campaign.read_dataset("out/")                       # pyarrow.Table, one row per run

Modules: `spec` (the YAML format, dotted parameter paths, run keys), `registry` (the scenario kinds: how each
loads, varies and runs its scenario), `runner` (Dask), `dataset` (the partitioned Parquet dataset).
"""

from __future__ import annotations

from pathlib import Path

from . import dataset, registry, spec
from .registry import KINDS, Kind, register
from .runner import run_campaign
from .spec import CampaignSpec, Run, builtin_names
from .spec import load as load_spec


def read_dataset(out, status: str | None = "done"):
    """The rows of the campaign in folder `out` (its `runs/` dataset) as a pyarrow Table; status None: all rows,
    with a `status` column."""
    return dataset.read(Path(out) / "runs", status)


__all__ = [
    "KINDS",
    "CampaignSpec",
    "Kind",
    "Run",
    "builtin_names",
    "dataset",
    "load_spec",
    "read_dataset",
    "register",
    "registry",
    "run_campaign",
    "spec",
]
