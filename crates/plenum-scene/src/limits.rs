//! Bounds every reader keeps, so that a small file can never ask for unbounded stack, memory
//! or time: how deep nesting may go, and whether a count read from a file can be backed by
//! the bytes that are left of it. (TOML's own parser bounds its nesting, at 80 levels.)

/// The deepest nesting of groups and transforms a reader accepts.
/// Far beyond what a scene needs, far below what overflows a thread's stack (the recursive
/// readers take well under 1 KiB a level; the smallest stack, a test thread's, is 2 MiB).
pub const MAX_NESTING: usize = 256;

/// Checks that `count` items, each taking at least `min_bytes` bytes, fit in the
/// `remaining` bytes of the file, before anything loops over them or allocates for them.
/// `what` names the items in the message ("vertices", "faces").
pub fn check_count(count: u64, min_bytes: u64, remaining: usize, what: &str) -> Result<(), String> {
    match count.checked_mul(min_bytes) {
        Some(needed) if needed <= remaining as u64 => Ok(()),
        _ => Err(format!(
            "the file asks for {count} {what}, but the {remaining} bytes left in it hold at \
             most {}: it is truncated or the count is wrong",
            remaining as u64 / min_bytes.max(1)
        )),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn counts_beyond_the_bytes_left_are_refused() {
        assert!(check_count(10, 4, 40, "values").is_ok());
        assert!(check_count(11, 4, 40, "values").is_err());
        // 2^64 − 1 items of 2 bytes overflow the product: refused, not wrapped.
        let e = check_count(u64::MAX, 2, 200, "vertices").unwrap_err();
        assert!(e.contains("hold at most 100"), "{e}");
    }
}
