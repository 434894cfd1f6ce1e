//! Whether a render's image buffers fit in the memory the process may still use, checked
//! before it starts: a film too large for the machine would otherwise abort mid-render.
//! The scene is loaded (and counted by the system) by then; this adds what the render
//! allocates per pixel.

use plenum_core::integrator::IntegratorKind;

/// Bytes per pixel a render allocates, by what it keeps per pixel, measured as peak resident
/// memory over 1024² pixels (December 2026: 250 bytes for Whitted's method, 280 for BDPT,
/// 670 for SPPM) and rounded up by a quarter: the raw film's sums (160 bytes) and the
/// image resolved from it, splats in fixed point (light tracing, BDPT: the buffer and the
/// film's copy), SPPM's visible points and its statistics (kept twice: the iteration's and
/// the film's), adaptive sampling's open flags.
pub fn bytes_per_pixel(kind: IntegratorKind, adaptive: bool, strategy_images: usize) -> u64 {
    let base = match kind {
        IntegratorKind::Sppm => 670,
        IntegratorKind::Light | IntegratorKind::Bdpt => 280,
        _ => 250,
    };
    let adaptive = if adaptive { 2 } else { 0 };
    // BDPT's strategy images: two films each (weighted and unweighted).
    let strategies = strategy_images as u64 * 2 * 68;
    (base + adaptive + strategies) * 5 / 4
}

/// The bytes this process may still allocate, and what bounds them: the least of the
/// system's available memory, the cgroup's limit and the address-space limit, of those
/// this system reports; `None` where it reports none (not Linux).
pub fn available() -> Option<(u64, &'static str)> {
    let read = |path: &str| std::fs::read_to_string(path).ok();
    let mut bounds = Vec::new();
    if let Some(b) = read("/proc/meminfo").and_then(|t| meminfo_available(&t)) {
        bounds.push((b, "MemAvailable in /proc/meminfo"));
    }
    if let (Some(max), Some(current)) = (
        read("/sys/fs/cgroup/memory.max").and_then(|t| t.trim().parse::<u64>().ok()),
        read("/sys/fs/cgroup/memory.current").and_then(|t| t.trim().parse::<u64>().ok()),
    ) {
        bounds.push((max.saturating_sub(current), "the cgroup's memory.max"));
    }
    if let (Some(limit), Some(used)) = (
        read("/proc/self/limits").and_then(|t| address_space_limit(&t)),
        read("/proc/self/status").and_then(|t| status_kib(&t, "VmSize:")),
    ) {
        bounds.push((
            limit.saturating_sub(used),
            "the address-space limit (ulimit -v)",
        ));
    }
    bounds.into_iter().min_by_key(|&(b, _)| b)
}

/// `MemAvailable` of /proc/meminfo, in bytes.
fn meminfo_available(text: &str) -> Option<u64> {
    status_kib(text, "MemAvailable:")
}

/// A `NAME: n kB` line's value in bytes (/proc/meminfo, /proc/self/status).
fn status_kib(text: &str, name: &str) -> Option<u64> {
    let line = text.lines().find(|l| l.starts_with(name))?;
    let kib: u64 = line[name.len()..].split_whitespace().next()?.parse().ok()?;
    kib.checked_mul(1024)
}

/// The soft "Max address space" of /proc/self/limits, in bytes; `None` when unlimited.
fn address_space_limit(text: &str) -> Option<u64> {
    let line = text.lines().find(|l| l.starts_with("Max address space"))?;
    line["Max address space".len()..]
        .split_whitespace()
        .next()?
        .parse()
        .ok()
}

/// Refuses a `width` × `height` render of `per_pixel` bytes a pixel that needs more than
/// `available` bytes, naming both.
pub fn check(
    width: u32,
    height: u32,
    per_pixel: u64,
    available: Option<(u64, &str)>,
) -> Result<(), String> {
    let need = width as u64 * height as u64 * per_pixel;
    match available {
        Some((have, what)) if need > have => Err(format!(
            "a {width}×{height} render needs about {} for its image buffers, but only {} is \
             available ({what}): render a smaller image, or free memory",
            gib(need),
            gib(have)
        )),
        _ => Ok(()),
    }
}

fn gib(bytes: u64) -> String {
    format!("{:.2} GiB", bytes as f64 / (1u64 << 30) as f64)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn limits_are_read_from_proc_text() {
        let meminfo =
            "MemTotal:       24000000 kB\nMemFree:        1000 kB\nMemAvailable:   2000000 kB\n";
        assert_eq!(meminfo_available(meminfo), Some(2_048_000_000));
        let limits = "Limit                     Soft Limit           Hard Limit           Units     \nMax address space         4000000000           unlimited            bytes     \n";
        assert_eq!(address_space_limit(limits), Some(4_000_000_000));
        let unlimited = limits.replace("4000000000 ", "unlimited  ");
        assert_eq!(address_space_limit(&unlimited), None);
        assert_eq!(
            status_kib("VmSize:\t  123 kB\n", "VmSize:"),
            Some(123 * 1024)
        );
    }

    #[test]
    fn a_film_larger_than_what_is_available_is_refused() {
        let per_pixel = bytes_per_pixel(IntegratorKind::Whitted, false, 0);
        let four_gb = Some((4u64 << 30, "a test"));
        // 16384² pixels, the largest size accepted, need some 59 GiB.
        let e = check(16384, 16384, per_pixel, four_gb).unwrap_err();
        assert!(e.contains("16384×16384") && e.contains("4.00 GiB"), "{e}");
        assert!(check(3072, 3072, per_pixel, four_gb).is_ok());
        assert!(check(16384, 16384, per_pixel, None).is_ok());
        // SPPM keeps far more per pixel.
        let sppm = bytes_per_pixel(IntegratorKind::Sppm, false, 0);
        assert!(check(4096, 4096, sppm, Some((1 << 30, "a test"))).is_err());
    }
}
