//! What the relight benches share: the process's CPU time and the load average, so that a
//! timing taken beside other work can be read (wall and CPU time side by side).
#![allow(dead_code)] // each bench uses part of it

/// CPU time of this process (all its threads, from each thread's `/proc/self/task/*/schedstat`,
/// nanosecond resolution), seconds; `None` where there is no such file.
pub fn cpu_s() -> Option<f64> {
    let mut ns = 0u64;
    for task in std::fs::read_dir("/proc/self/task").ok()? {
        let stat = std::fs::read_to_string(task.ok()?.path().join("schedstat")).ok()?;
        ns += stat.split_whitespace().next()?.parse::<u64>().ok()?;
    }
    Some(ns as f64 * 1e-9)
}

/// The 1-minute load average (`/proc/loadavg`), `None` where there is none.
pub fn load_average() -> Option<f64> {
    std::fs::read_to_string("/proc/loadavg")
        .ok()?
        .split_whitespace()
        .next()?
        .parse()
        .ok()
}
