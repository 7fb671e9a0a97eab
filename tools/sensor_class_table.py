"""The table of docs/sensors.md ("Identification error by sensor class") from a campaign folder:

    freefloat campaign sensor_class_monte_carlo --out scl
    python tools/sensor_class_table.py scl

prints the median / 95th percentile of every estimator, sensor class, quantity and horizon as Markdown (the same
numbers `freefloat report scl` shows)."""

from __future__ import annotations

import argparse

from freefloat.campaign import dataset
from freefloat.identification import sensor_classes as scl


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("folder", help="the campaign's --out folder")
    a = ap.parse_args()
    rows = [r for r in dataset.read(f"{a.folder}/runs", status=None).to_pylist() if r.get("status") == "done"]
    print(scl.table(rows, scl.horizons_of(rows)))


if __name__ == "__main__":
    main()
