//! The processor's vector registers between dense linear algebra and scalar code.
//!
//! On x86-64 processors with AVX, faer's matrix-product kernels (hand-written AVX2 and
//! AVX-512 assembly) return with the upper halves of the vector registers still in use:
//! they end without `vzeroupper`. Until something clears that state, every legacy-SSE
//! instruction, which is what the scalar floating-point code of a crate built for baseline
//! x86-64 compiles to, pays a transition penalty. Measured on this project's machine (an
//! AVX-512 Xeon): ERBF's basis evaluation of 64 queries took 1.36 ms after a faer product
//! on the same thread and 0.13 ms otherwise.
//!
//! [`clear_upper_registers`] executes `vzeroupper` where the processor has AVX. Scalar
//! kernels that run after faer calls on the same thread (basis and kernel evaluations,
//! candidate screening) call it first; it costs a few cycles and changes no result.

/// Clears the upper halves of the vector registers (`vzeroupper`) when the processor
/// supports AVX (detected at run time, once); does nothing elsewhere. No value is changed:
/// compiled code keeps nothing in those halves across a call.
#[inline]
pub fn clear_upper_registers() {
    #[cfg(target_arch = "x86_64")]
    if std::arch::is_x86_feature_detected!("avx") {
        // SAFETY: `vzeroupper` requires AVX, detected just above. It zeroes bits 128 and up
        // of the vector registers, which the compiler treats as clobbered by the intrinsic
        // and in which no value of the caller lives.
        #[allow(unsafe_code)]
        unsafe {
            std::arch::x86_64::_mm256_zeroupper();
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Clearing the registers between two evaluations of the same scalar expression leaves
    /// its value bit for bit the same, with live floating-point values around the call.
    #[test]
    fn clearing_changes_no_value() {
        let xs: Vec<f64> = (0..64).map(|i| (i as f64 * 0.37).sin()).collect();
        let before: f64 = xs.iter().map(|x| (-x * x).exp()).sum();
        clear_upper_registers();
        let after: f64 = xs.iter().map(|x| (-x * x).exp()).sum();
        assert_eq!(before.to_bits(), after.to_bits());
    }
}
