//! Fourier analysis of periodic boundary data by real FFT (SPEC §2).

use crate::Vec3;
use realfft::RealFftPlanner;
use std::f64::consts::PI;

/// A truncated real Fourier series `a₀ + Σ_{n=1}^{M} (aₙ cos nθ + bₙ sin nθ)` with vector
/// coefficients.
#[derive(Clone, Debug, PartialEq)]
pub struct FourierSeries {
    /// `a₀, a₁, …, a_M`.
    pub a: Vec<Vec3>,
    /// `b₀ (= 0), b₁, …, b_M`.
    pub b: Vec<Vec3>,
}

/// The sample count used to analyse `modes` modes: at least 8× oversampled (so the
/// retained modes are accurate, SPEC §2: ≥ 4×), a power of two, at least 64.
pub fn sample_count(modes: usize) -> usize {
    (8 * (modes + 1)).next_power_of_two().max(64)
}

impl FourierSeries {
    /// Analyses `f` on `[0, 2π)` from `samples` equispaced samples, keeping `modes` modes.
    ///
    /// ```
    /// use pdeshape_core::{Vec3, data::fourier::FourierSeries};
    /// let s = FourierSeries::analyse(|t| Vec3::new(1.0 + 2.0 * (3.0 * t).cos(), (t).sin(), 0.0), 4, 64);
    /// assert!((s.a[0].x - 1.0).abs() < 1e-14 && (s.a[3].x - 2.0).abs() < 1e-14);
    /// assert!((s.b[1].y - 1.0).abs() < 1e-14);
    /// ```
    pub fn analyse(f: impl Fn(f64) -> Vec3, modes: usize, samples: usize) -> Self {
        assert!(samples > 2 * modes, "{samples} samples cannot resolve {modes} modes");
        let pts: Vec<Vec3> = (0..samples).map(|k| f(2.0 * PI * k as f64 / samples as f64)).collect();
        Self::from_samples(&pts, modes)
    }

    /// Analyses equispaced samples `f(2πk/S)`, `k = 0 … S−1`.
    pub fn from_samples(pts: &[Vec3], modes: usize) -> Self {
        let s = pts.len();
        let mut planner = RealFftPlanner::<f64>::new();
        let fft = planner.plan_fft_forward(s);
        let mut a = vec![Vec3::ZERO; modes + 1];
        let mut b = vec![Vec3::ZERO; modes + 1];
        let mut input = fft.make_input_vec();
        let mut spec = fft.make_output_vec();
        for comp in 0..3 {
            for (x, p) in input.iter_mut().zip(pts) {
                *x = p[comp];
            }
            fft.process(&mut input, &mut spec).expect("FFT buffer sizes match");
            for n in 0..=modes.min(s / 2) {
                // Nyquist term (n = S/2) counts once.
                let w = if n == 0 || 2 * n == s { 1.0 } else { 2.0 } / s as f64;
                a[n][comp] = spec[n].re * w;
                b[n][comp] = -spec[n].im * w;
            }
        }
        FourierSeries { a, b }
    }

    /// Number of retained modes `M`.
    pub fn modes(&self) -> usize {
        self.a.len() - 1
    }

    /// `dᵏ/dθᵏ` of the series at θ.
    pub fn eval_derivative(&self, theta: f64, k: usize) -> Vec3 {
        let mut s = if k == 0 { self.a[0] } else { Vec3::ZERO };
        for n in 1..self.a.len() {
            let nf = n as f64;
            let ph = nf * theta + k as f64 * PI / 2.0;
            let (sn, cs) = ph.sin_cos();
            s += (self.a[n] * cs + self.b[n] * sn) * nf.powi(k as i32);
        }
        s
    }

    /// `out[j] = dʲ/dθʲ` of the series at θ for `j ≤ jmax`, from `cs[n] = (cos nθ, sin nθ)`
    /// (at least one entry per mode): `dʲ/dθʲ (a cos nθ + b sin nθ) =
    /// nʲ (a cos(nθ + jπ/2) + b sin(nθ + jπ/2))`, the phase shift taken exactly by
    /// permuting and negating `cos nθ`, `sin nθ` — one `sin_cos` per mode serves every
    /// series and every order at that θ.
    pub fn derivatives_from(&self, cs: &[(f64, f64)], jmax: usize) -> Vec<Vec3> {
        assert!(cs.len() >= self.a.len(), "cos nθ, sin nθ for every mode");
        (0..=jmax)
            .map(|j| {
                let mut s = if j == 0 { self.a[0] } else { Vec3::ZERO };
                for (n, ((a, b), &(c, sn))) in self.a.iter().zip(&self.b).zip(cs).enumerate().skip(1) {
                    let (cj, sj) = match j % 4 {
                        0 => (c, sn),
                        1 => (-sn, c),
                        2 => (-c, -sn),
                        _ => (sn, -c),
                    };
                    s += (*a * cj + *b * sj) * (n as f64).powi(j as i32);
                }
                s
            })
            .collect()
    }

    /// The series at θ.
    pub fn eval(&self, theta: f64) -> Vec3 {
        self.eval_derivative(theta, 0)
    }
}
