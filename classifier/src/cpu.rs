//! Which instruction sets the CPU runs, for the hot loops that are compiled once per set and
//! chosen at run time (`#[target_feature]` variants of one `#[inline(always)]` body). Every variant
//! uses plain IEEE operations only (no fused multiply-add), so all give the same bits.

/// Whether the CPU runs the variants compiled for AVX-512: AVX-512 F, BW, VL and DQ with AVX2,
/// BMI1 and BMI2. (The standard library caches the detection: a load and a test per call.)
#[cfg(target_arch = "x86_64")]
#[inline]
pub(crate) fn avx512() -> bool {
    std::arch::is_x86_feature_detected!("avx512f")
        && std::arch::is_x86_feature_detected!("avx512bw")
        && std::arch::is_x86_feature_detected!("avx512vl")
        && std::arch::is_x86_feature_detected!("avx512dq")
        && avx2_bmi()
}

/// Whether the CPU runs code compiled for AVX2, BMI1 and BMI2.
#[cfg(target_arch = "x86_64")]
#[inline]
pub(crate) fn avx2_bmi() -> bool {
    std::arch::is_x86_feature_detected!("avx2")
        && std::arch::is_x86_feature_detected!("bmi1")
        && std::arch::is_x86_feature_detected!("bmi2")
}

/// Stamps a hot function that picks its instruction set at run time: `fn $name(args) -> ret`
/// calls `$body` (an `#[inline(always)]` function of the same arguments) compiled for AVX-512
/// ([`avx512`]) where the CPU runs it, else compiled for the features `$avx2` where `$avx2_runs`
/// (a run-time check of those features) holds, else compiled for the baseline. One body, so every
/// variant does the same operations in the same order.
///
/// ```ignore
/// crate::cpu::dispatch_by_isa! {
///     /// Doc of the dispatching function.
///     pub(crate) fn sum(v: &[f32]) -> f32;
///     body: sum_body, avx2: "avx2" if std::arch::is_x86_feature_detected!("avx2")
/// }
/// ```
macro_rules! dispatch_by_isa {
    (
        $(#[$attr:meta])*
        $vis:vis fn $name:ident($($arg:ident: $ty:ty),* $(,)?) -> $ret:ty;
        body: $body:ident, avx2: $avx2:literal if $avx2_runs:expr $(,)?
    ) => {
        $(#[$attr])*
        $vis fn $name($($arg: $ty),*) -> $ret {
            /// The body compiled for AVX-512 ([`crate::cpu::avx512`]) (plain IEEE operations: the same results).
            #[cfg(target_arch = "x86_64")]
            #[target_feature(enable = "avx512f,avx512bw,avx512vl,avx512dq,avx2,bmi1,bmi2")]
            fn avx512($($arg: $ty),*) -> $ret {
                $body($($arg),*)
            }
            /// The body compiled for AVX2 (plain IEEE operations: the same results).
            #[cfg(target_arch = "x86_64")]
            #[target_feature(enable = $avx2)]
            fn avx2($($arg: $ty),*) -> $ret {
                $body($($arg),*)
            }
            #[cfg(target_arch = "x86_64")]
            if $crate::cpu::avx512() {
                // SAFETY: the CPU supports AVX-512 F, BW, VL and DQ, AVX2, BMI1 and BMI2 (checked just above).
                #[allow(unsafe_code)]
                unsafe {
                    return avx512($($arg),*);
                }
            }
            #[cfg(target_arch = "x86_64")]
            if $avx2_runs {
                // SAFETY: the CPU supports the features of the AVX2 variant (checked just above).
                #[allow(unsafe_code)]
                unsafe {
                    return avx2($($arg),*);
                }
            }
            $body($($arg),*)
        }
    };
}
pub(crate) use dispatch_by_isa;
