//! The Laplace map `M(ρ, φ)` between the trim loop and the domain border (SPEC §7,
//! paper 003 §3.1, with the bounded basis).
//!
//! `(∂ρ² + ∂φ²) M = 0` on `[0, 1] × [0, 2π)`, `M(0, φ) = C₁(φ)`, `M(1, φ) = C₂(φ)`.
//! Separation of variables gives
//!
//! `M = A₀(ρ) + Σ_{n=1}^{N} [A_n(ρ) cos nφ + B_n(ρ) sin nφ] + R(ρ, φ)`,
//!
//! with `A₀ = c₁,₀ (1 − ρ) + c₂,₀ ρ` and `A_n, B_n ∈ span{e^{−nρ}, e^{n(ρ−1)}}` (both
//! bounded by 1 on `[0, 1]`; the paper's eqs. 16–17 print `e^{anu}` and `u e^{−anu}`, of which
//! the second does not solve `A'' = n²A`). With Fourier coefficients `c₁,ₙ`, `c₂,ₙ` of the two
//! curves, `p e^{0} + q e^{−n} = c₁,ₙ` and `p e^{−n} + q = c₂,ₙ` give
//! `p = (c₁ − e^{−n} c₂)/(1 − e^{−2n})`, `q = (c₂ − e^{−n} c₁)/(1 − e^{−2n})`.
//! The remainder `R = r₁(φ) e^{−ωρ} + r₂(φ) e^{ω(ρ−1)}` is solved from the same 2 × 2 system
//! with the differences `D₁ = C₁ − F(0, ·)`, `D₂ = C₂ − F(1, ·)` at every `φ`, so both curves
//! are met exactly (round-off) wherever `M` is evaluated.

use super::curve::Uv;
use super::param::{InnerParam, OuterParam};
use super::region::TrimRegion;
use realfft::RealFftPlanner;
use std::f64::consts::TAU;

/// Samples per curve for the Fourier coefficients (independent of the mesh).
pub const FFT_SAMPLES: usize = 256;

/// The solved map.
#[derive(Clone, Debug)]
pub struct LaplaceMap {
    region: TrimRegion,
    inner: InnerParam,
    outer: OuterParam,
    modes: usize,
    omega: f64,
    /// `[c₁,₀, c₂,₀]`.
    mean: [Uv; 2],
    /// Per mode `n = 1 … N`: `[p_cos, p_sin, q_cos, q_sin]`.
    coef: Vec<[Uv; 4]>,
}

impl LaplaceMap {
    /// Solves the map with `modes` Fourier modes (`N`, at most `FFT_SAMPLES/2 − 1`) and the
    /// remainder rate `ω = N + 1`. With `columns`, the border corners fall on the mesh
    /// columns `φ = 2πj/columns`.
    pub fn new(region: TrimRegion, modes: usize, columns: Option<usize>) -> Self {
        crate::solves::record(crate::solves::SolveKind::LaplaceMap);
        let modes = modes.min(FFT_SAMPLES / 2 - 1);
        let inner = InnerParam::new(&region, columns);
        let c = region.center;
        let p0 = inner.point(&region, 0.0);
        let theta0 = (p0[1] - c[1]).atan2(p0[0] - c[0]);
        let outer = OuterParam::new(region.domain, c, theta0, columns);
        let k = FFT_SAMPLES;
        let c1: Vec<Uv> = (0..k).map(|j| inner.point(&region, TAU * j as f64 / k as f64)).collect();
        let c2: Vec<Uv> = (0..k).map(|j| outer.point(TAU * j as f64 / k as f64)).collect();
        let f1 = fourier(&c1, modes);
        let f2 = fourier(&c2, modes);
        let mut coef = Vec::with_capacity(modes);
        for n in 1..=modes {
            let e = (-(n as f64)).exp();
            let det = 1.0 - e * e;
            // p = (c₁ − e c₂)/det, q = (c₂ − e c₁)/det, for the cos and sin coefficients
            let p = |a: Uv, b: Uv| [(a[0] - e * b[0]) / det, (a[1] - e * b[1]) / det];
            let (cos1, sin1, cos2, sin2) = (f1[n].0, f1[n].1, f2[n].0, f2[n].1);
            coef.push([p(cos1, cos2), p(sin1, sin2), p(cos2, cos1), p(sin2, sin1)]);
        }
        LaplaceMap { region, inner, outer, modes, omega: (modes + 1) as f64, mean: [f1[0].0, f2[0].0], coef }
    }

    /// The trimmed region.
    pub fn region(&self) -> &TrimRegion {
        &self.region
    }

    /// Number of Fourier modes `N`.
    pub fn modes(&self) -> usize {
        self.modes
    }

    /// Remainder rate `ω`.
    pub fn omega(&self) -> f64 {
        self.omega
    }

    /// `C₁(φ)` (the trim loop).
    pub fn inner(&self, phi: f64) -> Uv {
        self.inner.point(&self.region, phi)
    }

    /// `C₂(φ)` (the domain border).
    pub fn outer(&self, phi: f64) -> Uv {
        self.outer.point(phi)
    }

    /// The Fourier part at `ρ = 0` and `ρ = 1` and its column functions
    /// `[P_n(φ), Q_n(φ)]` (so that `F = A₀ + Σ P_n e^{−nρ} + Q_n e^{n(ρ−1)}`).
    fn columns(&self, phi: f64, out: &mut Vec<Uv>) -> (Uv, Uv) {
        out.clear();
        let mut f0 = self.mean[0];
        let mut f1 = self.mean[1];
        let (s1, c1) = phi.sin_cos();
        let (mut s, mut c) = (s1, c1);
        for (i, r) in self.coef.iter().enumerate() {
            let e = (-((i + 1) as f64)).exp();
            let p = [r[0][0] * c + r[1][0] * s, r[0][1] * c + r[1][1] * s];
            let q = [r[2][0] * c + r[3][0] * s, r[2][1] * c + r[3][1] * s];
            for d in 0..2 {
                f0[d] += p[d] + e * q[d];
                f1[d] += e * p[d] + q[d];
            }
            out.push(p);
            out.push(q);
            (s, c) = (s * c1 + c * s1, c * c1 - s * s1);
        }
        (f0, f1)
    }

    /// The remainder functions `[r₁(φ), r₂(φ)]` from the boundary differences.
    fn remainder(&self, phi: f64, f0: Uv, f1: Uv) -> [Uv; 2] {
        let (a, b) = (self.inner(phi), self.outer(phi));
        let e = (-self.omega).exp();
        let det = 1.0 - e * e;
        let d1 = [a[0] - f0[0], a[1] - f0[1]];
        let d2 = [b[0] - f1[0], b[1] - f1[1]];
        [[(d1[0] - e * d2[0]) / det, (d1[1] - e * d2[1]) / det], [(d2[0] - e * d1[0]) / det, (d2[1] - e * d1[1]) / det]]
    }

    /// `M(ρ, φ)`.
    pub fn eval(&self, rho: f64, phi: f64) -> Uv {
        let mut cols = Vec::new();
        let (f0, f1) = self.columns(phi, &mut cols);
        let r = self.remainder(phi, f0, f1);
        let mut m = [0.0; 2];
        let rows = self.row_basis(rho);
        let (mean, rest) = rows.split_at(2);
        for d in 0..2 {
            m[d] = mean[0] * self.mean[0][d] + mean[1] * self.mean[1][d];
            for (k, col) in cols.iter().enumerate() {
                m[d] += rest[k] * col[d];
            }
            m[d] += rest[cols.len()] * r[0][d] + rest[cols.len() + 1] * r[1][d];
        }
        m
    }

    /// The `ρ` basis `[1 − ρ, ρ, e^{−ρ}, e^{ρ−1}, …, e^{−Nρ}, e^{N(ρ−1)}, e^{−ωρ}, e^{ω(ρ−1)}]`.
    fn row_basis(&self, rho: f64) -> Vec<f64> {
        let mut b = Vec::with_capacity(2 * self.modes + 4);
        b.push(1.0 - rho);
        b.push(rho);
        for n in 1..=self.modes {
            let n = n as f64;
            b.push((-n * rho).exp());
            b.push((n * (rho - 1.0)).exp());
        }
        b.push((-self.omega * rho).exp());
        b.push((self.omega * (rho - 1.0)).exp());
        b
    }

    /// `M` on the structured grid `ρ_i = i/(rings − 1)`, `φ_j = 2πj/columns`, row-major in
    /// `ρ` (ring 0 is the trim loop, the last ring the border). A product of a
    /// `rings × (2N + 4)` matrix of `ρ` functions with a `(2N + 4) × columns` matrix of `φ`
    /// functions.
    pub fn grid(&self, rings: usize, columns: usize) -> Vec<Uv> {
        let kk = 2 * self.modes + 4;
        // φ functions, one row per basis function, interleaved (x, y) per column
        let mut g = vec![0.0; kk * 2 * columns];
        let mut cols = Vec::with_capacity(2 * self.modes);
        for j in 0..columns {
            let phi = TAU * j as f64 / columns as f64;
            let (f0, f1) = self.columns(phi, &mut cols);
            let r = self.remainder(phi, f0, f1);
            let put = |g: &mut [f64], k: usize, v: Uv| {
                g[k * 2 * columns + 2 * j] = v[0];
                g[k * 2 * columns + 2 * j + 1] = v[1];
            };
            put(&mut g, 0, self.mean[0]);
            put(&mut g, 1, self.mean[1]);
            for (k, c) in cols.iter().enumerate() {
                put(&mut g, 2 + k, *c);
            }
            put(&mut g, kk - 2, r[0]);
            put(&mut g, kk - 1, r[1]);
        }
        // the product through faer's GEMM (one thread: the caller parallelises over
        // patches); the hand-written axpy per ring and basis function was 40 % of a
        // 140 × 170 grid's time, memory-bound on the output row
        let e_rows: Vec<Vec<f64>> = (0..rings).map(|i| self.row_basis(i as f64 / (rings - 1) as f64)).collect();
        let e = faer::Mat::<f64>::from_fn(rings, kk, |i, k| e_rows[i][k]);
        let gm = faer::Mat::<f64>::from_fn(kk, 2 * columns, |k, c| g[k * 2 * columns + c]);
        let mut out = faer::Mat::<f64>::zeros(rings, 2 * columns);
        faer::linalg::matmul::matmul(out.as_mut(), faer::Accum::Replace, e.as_ref(), gm.as_ref(), 1.0, faer::Par::Seq);
        crate::lanes::clear_upper();
        let mut p: Vec<Uv> = (0..rings)
            .flat_map(|i| (0..columns).map(move |j| (i, j)))
            .map(|(i, j)| [out[(i, 2 * j)], out[(i, 2 * j + 1)]])
            .collect();
        // The boundary rings are the curves themselves (equal to the sums up to round-off);
        // taking them exactly keeps the mesh's edges on the trim curve and the border.
        for j in 0..columns {
            let phi = TAU * j as f64 / columns as f64;
            p[j] = self.inner(phi);
            p[(rings - 1) * columns + j] = self.outer(phi);
        }
        p
    }
}

/// Fourier coefficients `(cos, sin)` of a sampled periodic plane curve, modes `0 … N`
/// (`sin` of mode 0 is zero).
fn fourier(p: &[Uv], modes: usize) -> Vec<(Uv, Uv)> {
    let k = p.len();
    let mut planner = RealFftPlanner::<f64>::new();
    let fft = planner.plan_fft_forward(k);
    let mut out = vec![([0.0; 2], [0.0; 2]); modes + 1];
    for d in 0..2 {
        let mut input: Vec<f64> = p.iter().map(|q| q[d]).collect();
        let mut spec = fft.make_output_vec();
        fft.process(&mut input, &mut spec).expect("FFT sizes are consistent");
        out[0].0[d] = spec[0].re / k as f64;
        for n in 1..=modes {
            out[n].0[d] = 2.0 * spec[n].re / k as f64;
            out[n].1[d] = -2.0 * spec[n].im / k as f64;
        }
    }
    out
}
