"""Reading and writing: telemetry files (Parquet or CSV with named columns, validated on reading; `telemetry`),
joint-trajectory files (JSON; `trajectory_files`) and the files shipped inside the package (`data`).
Simulated trajectories read and write themselves (`Trajectory.to_parquet` / `Trajectory.from_parquet`).

A new file reader goes here: a module that turns the file into a `Telemetry` (or a `Trajectory`) and names the
file, column and row of anything wrong; `Telemetry.from_file` dispatches on the suffix.
"""

from . import data, results, telemetry, trajectory_files
from .telemetry import Telemetry
from .trajectory_files import load_trajectory, save_trajectory

__all__ = ["Telemetry", "data", "load_trajectory", "results", "save_trajectory", "telemetry", "trajectory_files"]
