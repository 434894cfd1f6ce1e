//! The photon map: photons stored on surfaces, in a balanced kd-tree for k-nearest-neighbour
//! queries (Jensen, *Realistic Image Synthesis Using Photon Mapping*, 2001, §6: the
//! left-balanced tree kept implicitly in one array, each node the median of its range along
//! its widest axis).
//!
//! The tree is the photons' array reordered in place: the node of range [lo, hi) is the
//! photon at its middle, its children the halves on either side. Building it is a
//! deterministic selection per range, the two halves in parallel, so the same photons give
//! the same tree on any number of threads.

/// The least cosine between a photon's normal and the query's. On a sphere of radius R the
/// surface within distance r of a point has area π r², the disc the estimate divides by,
/// as long as every photon there counts: a tight bound (0.8, 37°) would leave out the
/// rim of that cap once r exceeds 0.6 R and make curved surfaces dark; cos 84° keeps it
/// to r ≈ 1.3 R and still excludes perpendicular walls.
pub const FACING: f32 = 0.1;

/// How far a photon may lie off the query's surface: the chord Δ from the query to the
/// photon, along the sum of their normals, at most this fraction of |Δ|. On a sphere (and a
/// plane) that component is exactly zero, (p − q)·(p + q − 2c)/R = 0, whatever the radius,
/// so curved surfaces keep all their photons; a surface parallel to the query's, a height
/// h away and facing the same way (a floor under a thin sheet of water, a table top over
/// the floor), has it 2h, and stays out of every search reaching less than 20 h. Without
/// it, final-gather rays that met a sheet's underside counted the photons of the floor's
/// underside 0.6 below: +36 % on that floor, +15 % on scenes/fresnel.toml's pool.
pub const SURFACE: f32 = 0.1;

/// One photon: where it landed, where it came from, its flux as linear sRGB.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Photon {
    pub p: [f32; 3],
    /// Unit direction back toward where the photon came from.
    pub wi: [f32; 3],
    /// The unit geometric normal where it landed: photons are gathered only from surfaces
    /// facing the same way as the query's, within [`FACING`] (not from the other side of a
    /// wall, or the perpendicular one in a corner).
    pub n: [f32; 3],
    /// Flux (W, or the scene's radiance unit × m² sr), linear sRGB, already divided by the
    /// number of photon paths of its pass.
    pub power: [f32; 3],
    /// Surface vertices from the light, 1 for the first hit.
    pub depth: u16,
    /// The kd-tree's split axis at this photon's node.
    axis: u8,
}

impl Photon {
    pub fn new(p: [f32; 3], wi: [f32; 3], n: [f32; 3], power: [f32; 3], depth: u16) -> Photon {
        Photon {
            p,
            wi,
            n,
            power,
            depth,
            axis: 0,
        }
    }
}

/// The most photons one query may gather.
pub const MAX_NEAREST: usize = 512;
// The setting's limit leaves room for the one more photon a search keeps.
const _: () = assert!(crate::settings::MAX_NEAREST as usize + 1 <= MAX_NEAREST);

/// What a query looks for.
#[derive(Clone, Copy, Debug)]
pub struct Query {
    pub p: [f32; 3],
    /// The query surface's unit geometric normal.
    pub n: [f32; 3],
    /// The most photons to gather, at most [`MAX_NEAREST`].
    pub k: usize,
    /// The largest squared distance searched.
    pub max_distance2: f32,
    /// Photons deeper than this are left out (see `photons.rs` on depth).
    pub max_depth: u16,
}

/// The k nearest photons found by a query: a max-heap on squared distance, in a fixed array
/// (nothing is allocated per query).
pub struct Nearest {
    found: [(f32, u32); MAX_NEAREST],
    len: usize,
}

impl Default for Nearest {
    fn default() -> Self {
        Nearest {
            found: [(0.0, 0); MAX_NEAREST],
            len: 0,
        }
    }
}

impl Nearest {
    /// The photons found, by index into the map, with their squared distances (unordered).
    pub fn found(&self) -> &[(f32, u32)] {
        &self.found[..self.len]
    }

    fn push(&mut self, k: usize, d2: f32, i: u32) {
        if self.len < k {
            let mut c = self.len;
            self.found[c] = (d2, i);
            self.len += 1;
            while c > 0 {
                let parent = (c - 1) / 2;
                if self.found[parent].0 >= self.found[c].0 {
                    break;
                }
                self.found.swap(parent, c);
                c = parent;
            }
        } else if d2 < self.found[0].0 {
            self.found[0] = (d2, i);
            let mut c = 0;
            loop {
                let (l, r) = (2 * c + 1, 2 * c + 2);
                let mut largest = c;
                if l < self.len && self.found[l].0 > self.found[largest].0 {
                    largest = l;
                }
                if r < self.len && self.found[r].0 > self.found[largest].0 {
                    largest = r;
                }
                if largest == c {
                    break;
                }
                self.found.swap(largest, c);
                c = largest;
            }
        }
    }

    /// The squared distance within which the heap is full, or the query's bound.
    fn bound(&self, k: usize, max_distance2: f32) -> f32 {
        if self.len == k {
            self.found[0].0
        } else {
            max_distance2
        }
    }

    /// The farthest photon found: the heap's top.
    pub fn farthest(&self) -> Option<(f32, u32)> {
        (self.len > 0).then(|| self.found[0])
    }
}

#[derive(Clone, Debug, Default)]
pub struct PhotonMap {
    photons: Vec<Photon>,
}

/// Ranges smaller than this are built on the calling thread.
const PARALLEL_RANGE: usize = 16_384;

impl PhotonMap {
    /// The map of `photons`, reordered into a kd-tree.
    pub fn build(mut photons: Vec<Photon>) -> PhotonMap {
        build_range(&mut photons);
        PhotonMap { photons }
    }

    pub fn len(&self) -> usize {
        self.photons.len()
    }

    pub fn is_empty(&self) -> bool {
        self.photons.is_empty()
    }

    pub fn photon(&self, i: u32) -> &Photon {
        &self.photons[i as usize]
    }

    /// The `q.k` photons nearest to `q.p` within its bound, facing its way, no deeper than
    /// its depth.
    pub fn nearest(&self, q: &Query, out: &mut Nearest) {
        out.len = 0;
        let k = q.k.clamp(1, MAX_NEAREST);
        self.search(0, self.photons.len(), q, k, out);
    }

    fn search(&self, lo: usize, hi: usize, q: &Query, k: usize, out: &mut Nearest) {
        if lo >= hi {
            return;
        }
        let mid = (lo + hi) / 2;
        let ph = &self.photons[mid];
        let axis = ph.axis as usize;
        let delta = q.p[axis] - ph.p[axis];
        // The near side first, so the far side is often cut off by the shrunken bound.
        let (near, far) = if delta < 0.0 {
            ((lo, mid), (mid + 1, hi))
        } else {
            ((mid + 1, hi), (lo, mid))
        };
        self.search(near.0, near.1, q, k, out);
        let d2: f32 = (0..3).map(|a| (q.p[a] - ph.p[a]).powi(2)).sum();
        if d2 < out.bound(k, q.max_distance2) && ph.depth <= q.max_depth {
            let facing: f32 = (0..3).map(|a| q.n[a] * ph.n[a]).sum();
            // The chord's component along the two normals' sum (see [`SURFACE`]).
            let along: f32 = (0..3)
                .map(|a| (ph.p[a] - q.p[a]) * (q.n[a] + ph.n[a]))
                .sum();
            if facing > FACING && along * along <= SURFACE * SURFACE * d2 {
                out.push(k, d2, mid as u32);
            }
        }
        if delta * delta < out.bound(k, q.max_distance2) {
            self.search(far.0, far.1, q, k, out);
        }
    }
}

fn build_range(photons: &mut [Photon]) {
    if photons.len() <= 1 {
        if let Some(p) = photons.first_mut() {
            p.axis = 0;
        }
        return;
    }
    let (mut lo, mut hi) = ([f32::INFINITY; 3], [f32::NEG_INFINITY; 3]);
    for p in photons.iter() {
        for a in 0..3 {
            lo[a] = lo[a].min(p.p[a]);
            hi[a] = hi[a].max(p.p[a]);
        }
    }
    let axis = (0..3)
        .max_by(|&a, &b| (hi[a] - lo[a]).total_cmp(&(hi[b] - lo[b])))
        .unwrap_or(0);
    let mid = photons.len() / 2;
    photons.select_nth_unstable_by(mid, |a, b| a.p[axis].total_cmp(&b.p[axis]));
    photons[mid].axis = axis as u8;
    let (left, rest) = photons.split_at_mut(mid);
    let right = &mut rest[1..];
    if left.len() >= PARALLEL_RANGE {
        rayon::join(|| build_range(left), || build_range(right));
    } else {
        build_range(left);
        build_range(right);
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::sampling::Rng;

    /// The kd-tree's k nearest are the brute-force k nearest, with the bound, the depth,
    /// the facing test and the surface test applied (2,000 random photons on three planes,
    /// 50 random queries on the middle one, seed 7).
    #[test]
    fn nearest_photons_match_brute_force() {
        let mut rng = Rng::new(7, 1);
        let mut photons = Vec::new();
        for i in 0..2000 {
            let p = [
                rng.uniform() as f32,
                [0.0, 0.5, 1.0][(i % 3) as usize],
                rng.uniform() as f32,
            ];
            let n = if i % 5 == 0 {
                [0.0, -1.0, 0.0]
            } else {
                [0.0, 1.0, 0.0]
            };
            photons.push(Photon::new(p, n, n, [1.0; 3], (i % 4) as u16 + 1));
        }
        let map = PhotonMap::build(photons.clone());
        assert_eq!(map.len(), 2000);
        let mut nearest = Nearest::default();
        for _ in 0..50 {
            let q = Query {
                p: [rng.uniform() as f32, 0.5, rng.uniform() as f32],
                n: [0.0, 1.0, 0.0],
                k: 20,
                max_distance2: 0.5,
                max_depth: 3,
            };
            map.nearest(&q, &mut nearest);
            let mut want: Vec<f32> = photons
                .iter()
                .filter(|ph| ph.depth <= 3 && ph.n[1] > 0.0 && ph.p[1] == 0.5)
                .map(|ph| distance2(&q, ph))
                .filter(|&d2| d2 < 0.5)
                .collect();
            want.sort_by(f32::total_cmp);
            want.truncate(20);
            let mut got: Vec<f32> = nearest.found().iter().map(|f| f.0).collect();
            got.sort_by(f32::total_cmp);
            assert_eq!(got, want);
            for &(d2, i) in nearest.found() {
                assert_eq!(distance2(&q, map.photon(i)), d2);
            }
        }
    }

    fn distance2(q: &Query, ph: &Photon) -> f32 {
        (0..3).map(|a| (q.p[a] - ph.p[a]).powi(2)).sum()
    }

    /// A sphere keeps all its photons: on a unit sphere, every photon within 1.2 of the
    /// query at its top whose normal is within the facing bound is found (800 photons on a
    /// Fibonacci lattice).
    #[test]
    fn a_curved_surface_keeps_its_photons() {
        let photons: Vec<Photon> = (0..800)
            .map(|i| {
                let z = 1.0 - (i as f32 + 0.5) / 400.0;
                let r = (1.0 - z * z).sqrt();
                let phi = i as f32 * 2.399_963;
                let n = [r * phi.cos(), z, r * phi.sin()];
                Photon::new(n, n, n, [1.0; 3], 1)
            })
            .collect();
        let map = PhotonMap::build(photons.clone());
        let q = Query {
            p: [0.0, 1.0, 0.0],
            n: [0.0, 1.0, 0.0],
            k: 512,
            max_distance2: 1.44,
            max_depth: 1,
        };
        let mut nearest = Nearest::default();
        map.nearest(&q, &mut nearest);
        let want = photons
            .iter()
            .filter(|ph| distance2(&q, ph) < 1.44 && ph.n[1] > FACING)
            .count();
        assert!(want > 100);
        assert_eq!(nearest.found().len(), want);
    }

    /// Photons on a plane parallel to the query's, a height 0.3 away and facing the same
    /// way, stay out of a search of radius 0.5 that reaches them, while those of the
    /// query's own plane are all found.
    #[test]
    fn a_search_keeps_to_its_own_surface() {
        let mut photons = Vec::new();
        for i in 0..400 {
            let (x, z) = ((i % 20) as f32 * 0.05 - 0.5, (i / 20) as f32 * 0.05 - 0.5);
            for y in [0.0, -0.3] {
                photons.push(Photon::new(
                    [x, y, z],
                    [0.0, 1.0, 0.0],
                    [0.0, 1.0, 0.0],
                    [1.0; 3],
                    1,
                ));
            }
        }
        let map = PhotonMap::build(photons);
        let q = Query {
            p: [0.0; 3],
            n: [0.0, 1.0, 0.0],
            k: 1000,
            max_distance2: 0.25,
            max_depth: 1,
        };
        let mut nearest = Nearest::default();
        map.nearest(&q, &mut nearest);
        let own = (0..400)
            .filter(|i| {
                let (x, z) = ((i % 20) as f32 * 0.05 - 0.5, (i / 20) as f32 * 0.05 - 0.5);
                x * x + z * z < 0.25
            })
            .count();
        assert!(own > 250);
        assert_eq!(nearest.found().len(), own);
        assert!(nearest
            .found()
            .iter()
            .all(|&(_, i)| map.photon(i).p[1] == 0.0));
    }
}
