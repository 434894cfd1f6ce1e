//! The uplift table's build time and accuracy per resolution (how `SRGB_TABLE_RES` was
//! chosen; docs/spectra.md): `cargo bench -p plenum-spectrum --bench uplift_table`.
//! The error is the largest difference of a round-tripped linear sRGB reflectance over 2000
//! random colours (a fixed-seed PCG), against the exact per-colour fit.

use plenum_spectrum::spectrum::reflectance_to_rgb;
use plenum_spectrum::{RgbSigmoid, RgbToSpectrumTable};

fn main() {
    let mut state = 7u64;
    let mut next = || {
        let old = state;
        state = old
            .wrapping_mul(6364136223846793005)
            .wrapping_add(1442695040888963407);
        let xorshifted = (((old >> 18) ^ old) >> 27) as u32;
        xorshifted.rotate_right((old >> 59) as u32) as f64 / 4294967296.0
    };
    let colours: Vec<[f64; 3]> = (0..2000).map(|_| [next(), next(), next()]).collect();
    let max_err =
        |a: [f64; 3], b: [f64; 3]| (0..3).map(|i| (a[i] - b[i]).abs()).fold(0.0, f64::max);
    let fit_worst = colours.iter().fold(0.0f64, |w, &rgb| {
        let s = RgbSigmoid::fit(rgb);
        w.max(max_err(rgb, reflectance_to_rgb(|l| s.eval(l))))
    });
    println!("exact fit: max err {fit_worst:.5}");
    for res in [8, 12, 16, 24, 32, 48, 64] {
        let t0 = std::time::Instant::now();
        let table = RgbToSpectrumTable::build(res);
        let dt = t0.elapsed();
        let (mut worst, mut mean) = (0.0f64, 0.0);
        for &rgb in &colours {
            let s = table.lookup(rgb);
            let e = max_err(rgb, reflectance_to_rgb(|l| s.eval(l)));
            worst = worst.max(e);
            mean += e / colours.len() as f64;
        }
        println!(
            "res {res:3}: build {:8.1} ms, max err {worst:.5}, mean err {mean:.6}",
            dt.as_secs_f64() * 1e3
        );
    }
}
