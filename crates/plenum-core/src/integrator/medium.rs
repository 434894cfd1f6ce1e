//! Which solids a ray is inside, so refraction uses the right pair of indices: entering a
//! glass ball inside water bends by η_glass/η_water, and leaving it returns to water.
//!
//! The stack records the solids' materials, not their indices, so that an index can be
//! looked up at the wavelength a path carries (a dispersive medium's η varies with λ).

use crate::material::MaterialId;

const CAPACITY: usize = 8;

/// A small fixed-capacity stack of (primitive, material): no allocation per ray. The
/// innermost solid is last; outside everything is vacuum.
#[derive(Clone, Copy, Debug)]
pub struct MediumStack {
    entries: [(u32, MaterialId); CAPACITY],
    len: usize,
}

impl Default for MediumStack {
    fn default() -> Self {
        MediumStack {
            entries: [(0, 0); CAPACITY],
            len: 0,
        }
    }
}

impl MediumStack {
    /// The material of the solid the ray is in now; `None` in vacuum.
    pub fn innermost(&self) -> Option<MaterialId> {
        self.len.checked_sub(1).map(|i| self.entries[i].1)
    }

    /// Index of refraction where the ray is now, with `ior` giving a material's (1 in
    /// vacuum).
    pub fn ior(&self, ior: impl Fn(MaterialId) -> f64) -> f64 {
        self.innermost().map_or(1.0, ior)
    }

    /// The stack after entering `primitive` of `material`. Deeper nesting than the capacity
    /// is treated as staying in the innermost medium recorded.
    pub fn entered(&self, primitive: u32, material: MaterialId) -> MediumStack {
        let mut s = *self;
        if s.len < CAPACITY {
            s.entries[s.len] = (primitive, material);
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
        // Materials 7 (water) and 9 (glass).
        let ior = |m: MaterialId| if m == 7 { 1.33 } else { 1.5 };
        let air = MediumStack::default();
        let water = air.entered(1, 7);
        let glass = water.entered(2, 9);
        assert_eq!(glass.ior(ior), 1.5);
        assert_eq!(glass.left(2).ior(ior), 1.33);
        assert_eq!(glass.left(2).left(1).ior(ior), 1.0);
        // Overlapping solids can be left out of order.
        assert_eq!(glass.left(1).ior(ior), 1.5);
    }
}
