//! Which solids a ray is inside, so refraction uses the right pair of indices: entering a
//! glass ball inside water bends by η_glass/η_water, and leaving it returns to water.

const CAPACITY: usize = 8;

/// A small fixed-capacity stack of (primitive, index of refraction): no allocation per ray.
/// The innermost solid is last; outside everything the index is that of vacuum, 1.
#[derive(Clone, Copy, Debug)]
pub struct MediumStack {
    entries: [(u32, f64); CAPACITY],
    len: usize,
}

impl Default for MediumStack {
    fn default() -> Self {
        MediumStack {
            entries: [(0, 1.0); CAPACITY],
            len: 0,
        }
    }
}

impl MediumStack {
    /// Index of refraction where the ray is now.
    pub fn ior(&self) -> f64 {
        if self.len == 0 {
            1.0
        } else {
            self.entries[self.len - 1].1
        }
    }

    /// The stack after entering `primitive`. Deeper nesting than the capacity is treated as
    /// staying in the innermost medium recorded.
    pub fn entered(&self, primitive: u32, ior: f64) -> MediumStack {
        let mut s = *self;
        if s.len < CAPACITY {
            s.entries[s.len] = (primitive, ior);
            s.len += 1;
        }
        s
    }

    /// The stack after leaving `primitive`, wherever it is in the stack (solids may overlap).
    pub fn left(&self, primitive: u32) -> MediumStack {
        let mut s = *self;
        if let Some(i) = s.entries[..s.len].iter().rposition(|e| e.0 == primitive) {
            s.entries.copy_within(i + 1..s.len, i);
            s.len -= 1;
        }
        s
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn glass_inside_water() {
        let air = MediumStack::default();
        let water = air.entered(1, 1.33);
        let glass = water.entered(2, 1.5);
        assert_eq!(glass.ior(), 1.5);
        assert_eq!(glass.left(2).ior(), 1.33);
        assert_eq!(glass.left(2).left(1).ior(), 1.0);
        // Overlapping solids can be left out of order.
        assert_eq!(glass.left(1).ior(), 1.5);
    }
}
