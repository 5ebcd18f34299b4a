//! The vector registers' upper lanes after faer's wide kernels.
//!
//! faer multiplies through the `gemm` crate, whose x86-64 kernels are chosen at run time:
//! on a CPU with AVX-512 they use the full 512-bit registers and return with the lanes above
//! bit 128 still holding data. This crate is compiled for the baseline x86-64, whose
//! scalar and 128-bit instructions (SSE) leave those upper lanes unchanged — so while they
//! hold data, each such instruction also depends on the register's previous contents, and
//! the processor can no longer overlap independent iterations of a loop.
//!
//! Measured on the development machine (AMD EPYC, AVX-512): the same loop over a 200 × 200
//! grid (a cross product, a square root and a division a vertex) took 0.23 ms on a thread
//! that had not run a GEMM and 0.90 ms on the rayon worker that had just computed the
//! grid's products; after `vzeroupper` on that worker, 0.23 ms again.
//!
//! [`clear_upper`] issues `vzeroupper`. Call it on the thread that ran the kernel, after a
//! faer product or factorisation and before scalar work.

/// Zeroes the upper lanes of the vector registers (`vzeroupper`) when the CPU has AVX;
/// does nothing elsewhere. Costs a few cycles; values in flight are unaffected (the code
/// around it holds no data above bit 128: the compiler models the intrinsic as clobbering
/// those lanes).
#[inline]
pub fn clear_upper() {
    #[cfg(target_arch = "x86_64")]
    if std::arch::is_x86_feature_detected!("avx") {
        // SAFETY: the CPU supports AVX (checked just above), which is all `vzeroupper`
        // needs; it changes no memory and no lane below bit 128.
        unsafe { std::arch::x86_64::_mm256_zeroupper() }
    }
}

/// `x`, after [`clear_upper`]: for wrapping a faer call, `lanes::after(a.partial_piv_lu())`.
#[inline]
pub fn after<T>(x: T) -> T {
    clear_upper();
    x
}

/// Whether the upper lanes of the vector registers hold data, as the processor reports it
/// (`XGETBV` with `ECX = 1`: the state components in use, bit 2 the upper halves of
/// `ymm0–15` and bit 6 the upper halves of `zmm0–15`); `None` where it cannot be asked.
#[cfg(test)]
pub(crate) fn upper_in_use() -> Option<bool> {
    #[cfg(target_arch = "x86_64")]
    {
        if !std::arch::is_x86_feature_detected!("xsave") || !std::arch::is_x86_feature_detected!("avx") {
            return None;
        }
        let leaf = std::arch::x86_64::__cpuid_count(0xd, 1);
        if leaf.eax & (1 << 2) == 0 {
            return None;
        }
        let (lo, _hi): (u32, u32);
        // SAFETY: XGETBV with ECX = 1 is supported (CPUID leaf 0Dh, sub-leaf 1, EAX bit 2,
        // checked above); it reads a register and writes EAX and EDX alone
        unsafe {
            std::arch::asm!("xgetbv", in("ecx") 1u32, out("eax") lo, out("edx") _hi, options(nomem, nostack, preserves_flags));
        }
        Some(lo & (1 << 2 | 1 << 6) != 0)
    }
    #[cfg(not(target_arch = "x86_64"))]
    None
}

#[cfg(test)]
mod tests {
    use super::*;
    use faer::Mat;

    /// A product large enough for faer's vector kernels leaves the upper lanes in use on a
    /// CPU with AVX-512 (where `gemm` runs its 512-bit kernels; elsewhere the kernels may
    /// clear them themselves, and the check of `clear_upper` below proves less), and
    /// `clear_upper` clears them.
    #[test]
    fn clear_upper_clears_what_a_product_leaves() {
        let Some(_) = upper_in_use() else {
            eprintln!("the processor does not report the registers' state: nothing to check");
            return;
        };
        let a = Mat::<f64>::from_fn(64, 64, |i, j| ((i * 7 + j * 3) % 11) as f64 - 5.0);
        let mut c = Mat::<f64>::zeros(64, 64);
        faer::linalg::matmul::matmul(c.as_mut(), faer::Accum::Replace, a.as_ref(), a.as_ref(), 1.0, faer::Par::Seq);
        let dirty = upper_in_use();
        clear_upper();
        let clean = upper_in_use();
        assert_eq!(c[(0, 0)], (0..64).map(|k| a[(0, k)] * a[(k, 0)]).sum::<f64>());
        #[cfg(target_arch = "x86_64")]
        if std::arch::is_x86_feature_detected!("avx512f") {
            assert_eq!(dirty, Some(true), "the product was expected to leave the upper lanes in use");
        }
        assert_eq!(clean, Some(false));
    }
}
