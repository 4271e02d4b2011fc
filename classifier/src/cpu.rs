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
