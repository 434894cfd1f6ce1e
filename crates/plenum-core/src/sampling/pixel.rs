//! The random numbers of a pixel's samples: where in the pixel each sample goes, and the
//! values it uses for the lens, the shutter time, the lights' areas and glossy directions.
//!
//! A pixel sample is a stream of values, one "dimension" after another: the pixel position
//! first, then the lens, the time, and whatever the integrator asks for along the way. How
//! the values of one dimension spread over the pixel's samples is the sampler's business:
//!
//! - `grid`: the pixel position on a regular √N×√N grid; the other dimensions stratified as
//!   for `jittered`.
//! - `random`: every value independent and uniform.
//! - `jittered`: each 2-D dimension split into √N×√N cells and each 1-D one into N strata;
//!   sample i takes one cell, jittered inside it. The pixel's cells go in order; the other
//!   dimensions' cells are shuffled per pixel and dimension, so the lens cell of a sample does
//!   not follow from its pixel cell.
//! - `cook16`: Cook's correlated scheme (Cook 1986): the pixel and every direction domain split
//!   into 16 regions; sub-pixel m pairs with one region of every domain through a table per
//!   dimension, each region taken once in 16 samples, each sample jittered inside its region.
//!   Cook used one table for the whole image. Then the regions of one dimension always meet
//!   the same regions of the next, in every pixel and for every seed, so a discrete choice
//!   made in one (a light, a lobe, Russian roulette) always sees the same part of the next: a
//!   bias that no number of samples removes. Here each pixel, and each pass of 16 samples,
//!   draws its own tables (a Latin hypercube over the regions: every pairing equally likely,
//!   so the estimate is unbiased), and the pairing sample m ↔ region table[m] stays.
//! - `sobol`: Owen-scrambled Sobol points (Burley 2020); each dimension takes a 2-D (or 1-D)
//!   Sobol set under its own scramble seed, so every pair is well stratified ("padding").
//!
//! **Invariant:** a value depends on (seed, pixel, sample index, dimension) only.

use super::Rng;

/// The most samples per pixel a render may ask for (a 256 × 256 grid; the Sobol sequence's
/// length).
pub const MAX_SPP: u32 = 1 << 16;

/// Dimensions past this many take plain random values: deep bounces gain little from
/// stratification.
const STRATIFIED_DIMENSIONS: u32 = 64;

#[derive(Clone, Copy, Debug, PartialEq)]
pub enum PixelSampler {
    /// Regular supersampling on an n × n grid of sub-pixel centres.
    Grid { n: u32 },
    /// `spp` independent uniform points.
    Random { spp: u32 },
    /// One uniform point in each cell of an n × n grid.
    Jittered { n: u32 },
    /// Cook's 16-region correlated pattern, `passes` times.
    Cook16 { passes: u32 },
    /// The first `spp` Owen-scrambled Sobol points.
    Sobol { spp: u32 },
}

/// The sampler kinds `--sampler` names (`adaptive` is a render mode built on `sobol`).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum SamplerKind {
    #[default]
    Grid,
    Random,
    Jittered,
    Cook16,
    Sobol,
}

impl SamplerKind {
    pub const NAMES: &'static str = "grid, random, jittered, cook16, sobol or adaptive";

    pub fn name(self) -> &'static str {
        match self {
            SamplerKind::Grid => "grid",
            SamplerKind::Random => "random",
            SamplerKind::Jittered => "jittered",
            SamplerKind::Cook16 => "cook16",
            SamplerKind::Sobol => "sobol",
        }
    }
}

impl std::str::FromStr for SamplerKind {
    type Err = String;
    fn from_str(s: &str) -> Result<Self, String> {
        match s {
            "grid" => Ok(SamplerKind::Grid),
            "random" => Ok(SamplerKind::Random),
            "jittered" => Ok(SamplerKind::Jittered),
            "cook16" => Ok(SamplerKind::Cook16),
            "sobol" => Ok(SamplerKind::Sobol),
            _ => Err(format!(
                "unknown sampler `{s}`: expected {}",
                SamplerKind::NAMES
            )),
        }
    }
}

impl PixelSampler {
    /// The regular grid closest to `spp` samples: n = round(√spp), from 1 to 256.
    pub fn grid_for(spp: u32) -> PixelSampler {
        PixelSampler::Grid {
            n: ((spp as f64).sqrt().round() as u32).clamp(1, 256),
        }
    }

    /// A `kind` sampler of about `spp` samples: exactly `spp` for random and sobol, the
    /// nearest square for the grid patterns, the nearest multiple of 16 for cook16.
    pub fn new(kind: SamplerKind, spp: u32) -> PixelSampler {
        let spp = spp.clamp(1, MAX_SPP);
        let n = ((spp as f64).sqrt().round() as u32).clamp(1, 256);
        match kind {
            SamplerKind::Grid => PixelSampler::Grid { n },
            SamplerKind::Random => PixelSampler::Random { spp },
            SamplerKind::Jittered => PixelSampler::Jittered { n },
            SamplerKind::Cook16 => PixelSampler::Cook16 {
                passes: ((spp + 8) / 16).max(1),
            },
            SamplerKind::Sobol => PixelSampler::Sobol { spp },
        }
    }

    /// Which pattern this is.
    pub fn kind(&self) -> SamplerKind {
        match self {
            PixelSampler::Grid { .. } => SamplerKind::Grid,
            PixelSampler::Random { .. } => SamplerKind::Random,
            PixelSampler::Jittered { .. } => SamplerKind::Jittered,
            PixelSampler::Cook16 { .. } => SamplerKind::Cook16,
            PixelSampler::Sobol { .. } => SamplerKind::Sobol,
        }
    }

    pub fn samples_per_pixel(&self) -> u32 {
        match *self {
            PixelSampler::Grid { n } | PixelSampler::Jittered { n } => n * n,
            PixelSampler::Random { spp } | PixelSampler::Sobol { spp } => spp,
            PixelSampler::Cook16 { passes } => 16 * passes,
        }
    }

    /// The values of sample `index` of pixel (x, y).
    pub fn stream(&self, seed: u64, x: u32, y: u32, index: u32) -> SampleStream {
        SampleStream {
            sampler: *self,
            index,
            pixel_key: mix32(seed ^ mix64(((y as u64) << 32) | x as u64)),
            rng: Rng::for_sample(seed, x, y, index),
            dimension: 0,
        }
    }
}

/// The values of one pixel sample, dimension after dimension: take [`SampleStream::pixel`]
/// first, then 1-D and 2-D values in a fixed order (the camera's lens and time, then what the
/// integrator needs).
#[derive(Clone, Debug)]
pub struct SampleStream {
    sampler: PixelSampler,
    index: u32,
    /// A hash of (seed, pixel): scrambles and shuffles differ from pixel to pixel.
    pixel_key: u32,
    rng: Rng,
    dimension: u32,
}

impl SampleStream {
    /// A stream of independent uniform values only (for samples placed by other means, such
    /// as adaptive subdivision's corners).
    pub fn random(rng: Rng) -> SampleStream {
        SampleStream {
            sampler: PixelSampler::Random { spp: 1 },
            index: 0,
            pixel_key: 0,
            rng,
            dimension: 1,
        }
    }

    /// The sample's position in the pixel, in [0, 1)²: the stream's first dimension.
    pub fn pixel(&mut self) -> [f64; 2] {
        debug_assert_eq!(self.dimension, 0, "the pixel position comes first");
        self.dimension = 1;
        let i = self.index;
        match self.sampler {
            PixelSampler::Grid { n } => {
                let (cx, cy) = (i % n, i / n);
                [(cx as f64 + 0.5) / n as f64, (cy as f64 + 0.5) / n as f64]
            }
            PixelSampler::Jittered { n } => self.cell_2d(i, n),
            _ => self.next_2d_at(0),
        }
    }

    /// The next 2-D value, in [0, 1)².
    pub fn next_2d(&mut self) -> [f64; 2] {
        self.dimension = self.dimension.max(1);
        let d = self.dimension;
        self.dimension += 1;
        self.next_2d_at(d)
    }

    /// The next 1-D value, in [0, 1).
    pub fn next_1d(&mut self) -> f64 {
        self.dimension = self.dimension.max(1);
        let d = self.dimension;
        self.dimension += 1;
        if d >= STRATIFIED_DIMENSIONS {
            return self.rng.uniform();
        }
        let i = self.index;
        match self.sampler {
            PixelSampler::Random { .. } => self.rng.uniform(),
            PixelSampler::Grid { n } | PixelSampler::Jittered { n } => {
                let strata = n * n;
                let s = permute(i, strata, self.key(d));
                (s as f64 + self.rng.uniform()) / strata as f64
            }
            PixelSampler::Cook16 { .. } => {
                let s = permute(i % 16, 16, self.pass_key(d));
                (s as f64 + self.rng.uniform()) / 16.0
            }
            PixelSampler::Sobol { .. } => sobol_burley::sample(i, 0, self.key(d)) as f64,
        }
    }

    /// Passes over the next 2-D value without working it out, leaving the stream as
    /// [`next_2d`](Self::next_2d) would (the same random numbers drawn): for a value nobody
    /// reads, such as a pinhole camera's lens point, whose permutation and hashes cost a
    /// cheap camera ray a tenth of its time.
    pub fn skip_2d(&mut self) {
        self.skip(2);
    }

    /// [`skip_2d`](Self::skip_2d) for a 1-D value (a still scene's shutter time).
    pub fn skip_1d(&mut self) {
        self.skip(1);
    }

    /// Passes over a value of `lanes` dimensions' random numbers.
    fn skip(&mut self, lanes: u32) {
        self.dimension = self.dimension.max(1);
        let d = self.dimension;
        self.dimension += 1;
        let draws = match self.sampler {
            PixelSampler::Sobol { .. } if d < STRATIFIED_DIMENSIONS => 0,
            _ => lanes,
        };
        for _ in 0..draws {
            self.rng.next_u32();
        }
    }

    fn next_2d_at(&mut self, d: u32) -> [f64; 2] {
        if d >= STRATIFIED_DIMENSIONS {
            return [self.rng.uniform(), self.rng.uniform()];
        }
        let i = self.index;
        match self.sampler {
            PixelSampler::Random { .. } => [self.rng.uniform(), self.rng.uniform()],
            PixelSampler::Grid { n } | PixelSampler::Jittered { n } => {
                let cell = permute(i, n * n, self.key(d));
                self.cell_2d(cell, n)
            }
            PixelSampler::Cook16 { .. } => {
                // The pixel itself (d = 0) takes its regions in order: sample m in
                // sub-pixel m, paired through this pixel's and pass's tables.
                let m = i % 16;
                let region = if d == 0 {
                    m
                } else {
                    permute(m, 16, self.pass_key(d))
                };
                self.cell_2d(region, 4)
            }
            PixelSampler::Sobol { .. } => {
                let key = self.key(d);
                [
                    sobol_burley::sample(i, 0, key) as f64,
                    sobol_burley::sample(i, 1, key) as f64,
                ]
            }
        }
    }

    /// A uniform point in cell `cell` of an n × n grid over [0, 1)², cells row by row.
    fn cell_2d(&mut self, cell: u32, n: u32) -> [f64; 2] {
        let (cx, cy) = (cell % n, cell / n);
        let (u, v) = (self.rng.uniform(), self.rng.uniform());
        [(cx as f64 + u) / n as f64, (cy as f64 + v) / n as f64]
    }

    /// The scramble or shuffle key of dimension `d` in this pixel.
    fn key(&self, d: u32) -> u32 {
        mix32(((self.pixel_key as u64) << 32) | d as u64)
    }

    /// cook16's table key of dimension `d` in this pixel and pass of 16 samples.
    fn pass_key(&self, d: u32) -> u32 {
        mix32(((self.key(d) as u64) << 32) | (self.index / 16) as u64)
    }
}

/// A pseudo-random permutation of 0..n picked by `key`: a bijective hash on the next power
/// of two, repeated until it lands below n (cycle walking keeps it a bijection on 0..n).
pub fn permute(i: u32, n: u32, key: u32) -> u32 {
    debug_assert!(i < n);
    if n <= 1 {
        return 0;
    }
    let mask = n.next_power_of_two() - 1;
    let bits = mask.count_ones();
    let mut x = i;
    loop {
        // Each step is a bijection of the `bits`-bit integers.
        x ^= key & mask;
        x = x.wrapping_mul(0x9E37_79B1 | 1) & mask;
        x ^= x >> (bits / 2 + 1);
        x = x.wrapping_add(key >> 16) & mask;
        x = x.wrapping_mul(0x85EB_CA77) & mask;
        x ^= x >> (bits / 3 + 1);
        if x < n {
            return x;
        }
    }
}

/// SplitMix64's finaliser.
fn mix64(mut z: u64) -> u64 {
    z = (z ^ (z >> 30)).wrapping_mul(0xbf58476d1ce4e5b9);
    z = (z ^ (z >> 27)).wrapping_mul(0x94d049bb133111eb);
    z ^ (z >> 31)
}

fn mix32(z: u64) -> u32 {
    (mix64(z) >> 32) as u32
}

#[cfg(test)]
mod tests {
    use super::*;

    fn pixel_positions(s: PixelSampler, seed: u64) -> Vec<[f64; 2]> {
        (0..s.samples_per_pixel())
            .map(|i| s.stream(seed, 3, 5, i).pixel())
            .collect()
    }

    /// After `skip_2d` (`skip_1d`) every later value is the one it is after `next_2d`
    /// (`next_1d`), for every sampler, in the stratified dimensions and past them.
    #[test]
    fn skipping_a_value_leaves_the_stream_as_drawing_it_does() {
        let samplers = [
            PixelSampler::Grid { n: 4 },
            PixelSampler::Random { spp: 16 },
            PixelSampler::Jittered { n: 4 },
            PixelSampler::Cook16 { passes: 1 },
            PixelSampler::Sobol { spp: 16 },
        ];
        for s in samplers {
            for index in [0, 5, 15] {
                for before in [0, 1, 2, STRATIFIED_DIMENSIONS] {
                    let [mut a, mut b] = [0, 1].map(|_| s.stream(9, 3, 7, index));
                    assert_eq!(a.pixel(), b.pixel());
                    for _ in 0..before {
                        assert_eq!(a.next_1d(), b.next_1d());
                    }
                    a.next_2d();
                    b.skip_2d();
                    a.next_1d();
                    b.skip_1d();
                    for _ in 0..4 {
                        assert_eq!(a.next_1d(), b.next_1d(), "{s:?} {index} {before}");
                        assert_eq!(a.next_2d(), b.next_2d(), "{s:?} {index} {before}");
                    }
                }
            }
        }
    }

    #[test]
    fn grid_covers_the_pixel_evenly() {
        let s = PixelSampler::grid_for(16);
        assert_eq!(s.samples_per_pixel(), 16);
        let offsets = pixel_positions(s, 0);
        assert_eq!(offsets[0], [0.125, 0.125]);
        assert_eq!(offsets[15], [0.875, 0.875]);
        let mean_x = offsets.iter().map(|o| o[0]).sum::<f64>() / 16.0;
        assert!((mean_x - 0.5).abs() < 1e-15);
        assert_eq!(pixel_positions(PixelSampler::grid_for(1), 0)[0], [0.5, 0.5]);
    }

    #[test]
    fn permutations_are_bijections() {
        for n in [1, 2, 3, 7, 16, 100, 1000] {
            for key in [0, 1, 0xdead_beef, 12345] {
                let mut seen = vec![false; n as usize];
                for i in 0..n {
                    let p = permute(i, n, key) as usize;
                    assert!(!seen[p], "n {n} key {key}");
                    seen[p] = true;
                }
            }
        }
        // Different keys shuffle differently.
        let a: Vec<u32> = (0..16).map(|i| permute(i, 16, 1)).collect();
        let b: Vec<u32> = (0..16).map(|i| permute(i, 16, 2)).collect();
        assert_ne!(a, b);
    }

    /// Every stratified sampler puts exactly one sample in each cell of every dimension:
    /// the pixel, two later 2-D dimensions and a 1-D one.
    #[test]
    fn stratified_samplers_fill_every_cell_of_every_dimension() {
        for s in [
            PixelSampler::Jittered { n: 4 },
            PixelSampler::Grid { n: 4 },
            PixelSampler::Cook16 { passes: 1 },
            PixelSampler::Sobol { spp: 16 },
        ] {
            let mut cells = [[[false; 16]; 3]; 2];
            let mut strata = [false; 16];
            for pixel in 0..2u32 {
                for i in 0..16 {
                    let mut st = s.stream(9, pixel, 0, i);
                    let values = [st.pixel(), st.next_2d(), st.next_2d()];
                    for (d, v) in values.iter().enumerate() {
                        let c = (v[0] * 4.0) as usize + 4 * (v[1] * 4.0) as usize;
                        assert!(!cells[pixel as usize][d][c], "{s:?} dim {d}");
                        cells[pixel as usize][d][c] = true;
                    }
                    if pixel == 0 {
                        let t = (st.next_1d() * 16.0) as usize;
                        assert!(!strata[t], "{s:?} 1-D");
                        strata[t] = true;
                    }
                }
            }
        }
    }

    /// Jittered: the lens cell of a sample is not its pixel cell (shuffled per dimension);
    /// cook16: sample m pairs sub-pixel m with a region of each domain, by a table that
    /// differs from pixel to pixel and from one pass of 16 to the next.
    #[test]
    fn jittered_shuffles_dimensions_and_cook16_draws_its_tables_per_pixel_and_pass() {
        let cell = |v: [f64; 2]| (v[0] * 4.0) as u32 + 4 * (v[1] * 4.0) as u32;
        let pairs = |s: PixelSampler, x: u32, pass: u32| -> Vec<(u32, u32)> {
            (0..16)
                .map(|i| {
                    let mut st = s.stream(1, x, 0, 16 * pass + i);
                    (cell(st.pixel()), cell(st.next_2d()))
                })
                .collect()
        };
        let j = PixelSampler::Jittered { n: 4 };
        assert!(pairs(j, 0, 0).iter().any(|(a, b)| a != b));
        assert_ne!(pairs(j, 0, 0), pairs(j, 1, 0));
        let c = PixelSampler::Cook16 { passes: 2 };
        for x in [0, 7] {
            for pass in [0, 1] {
                let p = pairs(c, x, pass);
                assert!(p.iter().enumerate().all(|(m, &(a, _))| a == m as u32));
            }
        }
        assert_ne!(pairs(c, 0, 0), pairs(c, 7, 0));
        assert_ne!(pairs(c, 0, 0), pairs(c, 0, 1));
    }

    /// A choice made in one dimension meets the next without bias: the mean over pixels of
    /// [u_d < ½]·[u_(d+1) < ½] is ¼ for every pair of consecutive dimensions (1-D and 2-D
    /// alike). Cook's single table gave each pair a fixed count out of 16 in every pixel
    /// (3/16 or 5/16 instead of 4/16, whatever the samples). 4096 pixels of 16 samples, seed 3;
    /// a pixel's estimate has standard deviation 0.065 (hypergeometric), the mean 0.001:
    /// tolerance 0.005.
    #[test]
    fn cook16_pairs_dimensions_without_bias() {
        let c = PixelSampler::Cook16 { passes: 1 };
        let pixels = 4096u32;
        for kind in ["1-D", "2-D"] {
            let mut sums = [0.0; 8];
            for p in 0..pixels {
                for i in 0..16 {
                    let mut st = c.stream(3, p % 64, p / 64, i);
                    st.pixel();
                    let u: Vec<f64> = (0..9)
                        .map(|_| {
                            if kind == "1-D" {
                                st.next_1d()
                            } else {
                                st.next_2d()[0]
                            }
                        })
                        .collect();
                    for d in 0..8 {
                        if u[d] < 0.5 && u[d + 1] < 0.5 {
                            sums[d] += 1.0 / 16.0;
                        }
                    }
                }
            }
            for (d, s) in sums.iter().enumerate() {
                let m = s / pixels as f64;
                assert!(
                    (m - 0.25).abs() < 0.005,
                    "{kind} dimensions {d}, {}: {m}",
                    d + 1
                );
            }
        }
    }

    #[test]
    fn sampler_sizes_and_names() {
        assert_eq!(
            PixelSampler::new(SamplerKind::Jittered, 16),
            PixelSampler::Jittered { n: 4 }
        );
        assert_eq!(
            PixelSampler::new(SamplerKind::Random, 10).samples_per_pixel(),
            10
        );
        assert_eq!(
            PixelSampler::new(SamplerKind::Cook16, 40).samples_per_pixel(),
            48
        );
        assert_eq!(
            PixelSampler::new(SamplerKind::Cook16, 1).samples_per_pixel(),
            16
        );
        assert_eq!("sobol".parse::<SamplerKind>(), Ok(SamplerKind::Sobol));
        assert!("halton"
            .parse::<SamplerKind>()
            .unwrap_err()
            .contains("jittered"));
    }

    /// Estimating the area of a pixel below a random edge: random sampling's RMS error
    /// falls as 1/√N; jittered and Sobol sampling's faster (as N^-3/4 for edges), so they are
    /// smaller at equal N. 4000 random edges, seeds fixed; tolerances are factors of two
    /// around the expected ratios, many standard errors wide.
    #[test]
    fn stratified_samplers_beat_random_on_edges() {
        let rmse = |kind: SamplerKind, spp: u32| {
            let sampler = PixelSampler::new(kind, spp);
            let mut edges = Rng::new(99, 1);
            let mut sum = 0.0;
            let trials = 4000;
            for t in 0..trials {
                // The edge y = a + b·(x − ½) through the pixel; exact area below it (clamped
                // by integrating over 1000 columns, which is exact enough here).
                let a = edges.uniform();
                let b = (edges.uniform() - 0.5) * 4.0;
                let inside = |p: [f64; 2]| p[1] < a + b * (p[0] - 0.5);
                let exact = (0..1000)
                    .map(|k| {
                        let x = (k as f64 + 0.5) / 1000.0;
                        (a + b * (x - 0.5)).clamp(0.0, 1.0)
                    })
                    .sum::<f64>()
                    / 1000.0;
                let n = sampler.samples_per_pixel();
                let hits = (0..n)
                    .filter(|&i| inside(sampler.stream(5, t, 0, i).pixel()))
                    .count();
                let err = hits as f64 / n as f64 - exact;
                sum += err * err;
            }
            (sum / trials as f64).sqrt()
        };
        let (r16, r64) = (rmse(SamplerKind::Random, 16), rmse(SamplerKind::Random, 64));
        // Random: 4× the samples, half the error.
        assert!((r16 / r64 - 2.0).abs() < 0.4, "random {r16} -> {r64}");
        for kind in [SamplerKind::Jittered, SamplerKind::Sobol] {
            let (s16, s64) = (rmse(kind, 16), rmse(kind, 64));
            // Smaller than random at equal N, and falling faster.
            assert!(s16 < 0.7 * r16 && s64 < 0.6 * r64, "{kind:?} {s16}, {s64}");
            assert!(s16 / s64 > 2.2, "{kind:?} {s16} -> {s64}");
        }
    }
}
