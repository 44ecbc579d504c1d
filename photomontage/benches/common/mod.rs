//! What the relight benches share: the process's CPU time and the load average, so that a
//! timing taken beside other work can be read (wall and CPU time side by side), and the
//! interreflected radiosity per element that compares two hierarchies of the same elements.
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

/// Interreflected radiosity (B − ρ·E_direct, green) and area per element, keyed by the
/// element's centroid in millimetres (meshes with other roots have the same elements in another
/// order).
pub fn indirect_by_centroid(
    s: &photomontage::radiosity::Solution,
) -> std::collections::HashMap<[i64; 3], (f64, f64)> {
    let total = s.total_radiosity_rgb();
    (0..total.len())
        .map(|e| {
            let node = s.mesh.element_node(e);
            let rho = s.mesh.surfaces[node.surface as usize].reflectance_rgb[1];
            let direct: f64 = s.groups.iter().map(|g| g.direct_irradiance_rgb[e][1]).sum();
            let v = &node.vertices_in_world_m;
            let c = (v[0].coords + v[1].coords + v[2].coords) / 3.0;
            #[allow(clippy::cast_possible_truncation)]
            let key = [c.x, c.y, c.z].map(|x| (x * 1000.0).round() as i64);
            (key, (total[e][1] - rho * direct, node.area_m2))
        })
        .collect()
}
