//! The choice, at run time, of wider vector instructions for the exact likelihood's inner
//! loops.
//!
//! The workspace is built for the baseline x86-64 (two doubles to a vector instruction), so
//! that its binaries run anywhere. The few loops that evaluate every quadrature node of the
//! exact likelihood are also compiled for AVX2 (four doubles) and that copy is taken when the
//! processor has it. The copies run the same additions and multiplications in the same order
//! (Rust never fuses a multiplication and an addition on its own), so both give the same bits.

/// Whether the processor has AVX2 (checked once).
#[cfg(target_arch = "x86_64")]
pub(crate) fn has_avx2() -> bool {
    use std::sync::OnceLock;
    static HAS: OnceLock<bool> = OnceLock::new();
    *HAS.get_or_init(|| std::is_x86_feature_detected!("avx2"))
}
