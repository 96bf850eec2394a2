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

/// Defines `fn $name(args) -> ret { body }` compiled twice, for the baseline and for AVX2, and
/// calling the AVX2 copy when [`has_avx2`] says the processor has it. The body is the same
/// code in both copies, so the values are too.
macro_rules! baseline_or_avx2 {
    (
        $(#[$meta:meta])*
        fn $name:ident($($arg:ident: $ty:ty),* $(,)?) $(-> $ret:ty)? $body:block
    ) => {
        $(#[$meta])*
        #[inline]
        fn $name($($arg: $ty),*) $(-> $ret)? {
            #[inline(always)]
            fn kernel($($arg: $ty),*) $(-> $ret)? $body
            #[cfg(target_arch = "x86_64")]
            #[target_feature(enable = "avx2")]
            fn wide($($arg: $ty),*) $(-> $ret)? {
                kernel($($arg),*)
            }
            #[cfg(target_arch = "x86_64")]
            if $crate::simd::has_avx2() {
                // SAFETY: the processor has AVX2 (checked at run time), the only feature
                // `wide` needs.
                return unsafe { wide($($arg),*) };
            }
            kernel($($arg),*)
        }
    };
}
pub(crate) use baseline_or_avx2;
