//! What the processor offers that the kernels rely on.
//!
//! Kernels evaluate `a * b + c` as one fused multiply-add (one rounding,
//! `f64::mul_add`): a third fewer arithmetic instructions in the EOM. The
//! compiled kernels are built with the instruction enabled, so they may
//! only run where the processor has it; the interpreter takes the same
//! fused operations from the hardware when it can and from libm's exact
//! software `fma` when not, so both backends give the same bits anywhere.

/// Whether the compiled kernels can run here (x86-64: FMA3; every other
/// target either has a fused multiply-add or compiles `mul_add` without
/// a feature gate).
#[inline]
pub fn has_fma() -> bool {
    #[cfg(target_arch = "x86_64")]
    {
        std::arch::is_x86_feature_detected!("fma")
    }
    #[cfg(not(target_arch = "x86_64"))]
    {
        true
    }
}

/// Panics unless [`has_fma`]: generated kernels call this before running
/// code compiled for FMA (backends choose the interpreter without it, so
/// reaching the panic is a bug, not an input error).
#[inline]
pub fn require_fma() {
    assert!(
        has_fma(),
        "compiled kernels need a processor with fused multiply-add; use the interpreted backend"
    );
}
