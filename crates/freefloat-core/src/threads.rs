//! How many threads the engine's parallel passes may use.

use std::sync::OnceLock;

/// The cores this process may run on, read once and then kept.
///
/// `std::thread::available_parallelism` reads the process's cgroup files under /proc on every call (about
/// 80 µs here): called per call, it made a single `ff.aba` from Python 85 µs instead of about 1 µs. Kept, a
/// CPU affinity or quota changed after the first parallel call is not seen; it only sets how many threads a
/// pass starts, never a result (the passes' sums are merged in a fixed order).
pub fn available_cores() -> usize {
    static CORES: OnceLock<usize> = OnceLock::new();
    *CORES.get_or_init(|| std::thread::available_parallelism().map_or(1, |n| n.get()))
}
