//! Quasi-random interior points of the parameter cube, where a solid's diagnostics
//! (residuals, convergence) are measured: the boundary surfaces may have singular
//! derivatives on the cube's edges, so the points keep 0.02 away from its faces.

/// `n` points of `[0.02, 0.98]³`, the k-th at `0.02 + 0.96 · frac(k·α + β)` per axis with
/// the irrational steps `α = 0.618034, 0.414214, 0.732051` (golden ratio, √2 and √3 parts)
/// and offsets `β = 0.1, 0.2, 0.3`: a low-discrepancy sequence that every diagnostic of a
/// solid shares, so their figures are measured at the same places.
pub fn interior_points(n: usize) -> Vec<[f64; 3]> {
    (0..n)
        .map(|k| {
            let at = |a: f64, b: f64| 0.02 + 0.96 * (k as f64 * a + b).fract();
            [at(0.618034, 0.1), at(0.414214, 0.2), at(0.732051, 0.3)]
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn interior_points_fill_the_cube_away_from_its_faces() {
        let p = interior_points(512);
        assert_eq!(p.len(), 512);
        assert!(p.iter().flatten().all(|&x| (0.02..0.98).contains(&x)));
        // every one of the 8 octants holds between 1/16 and 1/4 of the points (a
        // uniform sample puts 1/8 there)
        let mut count = [0usize; 8];
        for q in &p {
            count[(0..3).map(|i| usize::from(q[i] > 0.5) << i).sum::<usize>()] += 1;
        }
        assert!(count.iter().all(|&c| (32..=128).contains(&c)), "{count:?}");
    }
}
