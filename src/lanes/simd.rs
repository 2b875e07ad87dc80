//! The instruction set the lane loop runs on, chosen at run time.

/// Which instruction set the ensemble's lane loop is compiled for.
///
/// The lane loop (the six stages, the error norm, the controller and the masked updates)
/// is compiled three times (in an optimized build, below): for the build's target (the
/// x86-64 baseline, SSE2, unless `RUSTFLAGS` says otherwise) in four lanes, with AVX2 and
/// FMA enabled and with AVX-512F enabled in sixteen lanes each (the
/// `pulp` crate's `V3` and `V4` tokens, created only where the CPU has the features, run
/// the inlined loop under those target features without `unsafe` in this crate). At
/// the start of every [`Ensemble::run`](crate::ensemble::Ensemble::run) the variant is picked by
/// [`resolve`](Self::resolve): [`Simd::Auto`] (the default) takes the widest the CPU
/// reports (`is_x86_feature_detected!`); on other architectures there is only the
/// baseline. The default build therefore gets the AVX2 or AVX-512 code without
/// `-C target-cpu`.
///
/// # Which builds have which variants
/// The AVX2 and AVX-512 variants are compiled in builds without debug assertions (the
/// `release` profile, `cargo run --release`, `cargo bench`): there their speed matters. A
/// build with debug assertions (the `dev` and `test` profiles: `cargo build`, `cargo test`)
/// compiles the baseline alone, so that a test build does not compile the lane loop three
/// times for every model; [`resolve`](Self::resolve) and [`available`](Self::available)
/// then report the baseline. The results are the same bits either way (below); CI runs the
/// ensemble's tests in both profiles.
///
/// # Same answers on every path
/// The variants differ in instruction selection only: every variant executes the same
/// IEEE operations (add, multiply, divide, `sqrt`, compare, blend, integer shifts of the
/// bits) in the same order; Rust never contracts `a·b + c` into a fused multiply-add
/// unless `mul_add` is called, and the lane step calls none (also not in the
/// [`LaneMath::Vector`] functions). Results are bit-identical across the variants in both
/// math modes (tested).
///
/// [`LaneMath::Vector`]: super::LaneMath::Vector
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Default)]
#[non_exhaustive]
pub enum Simd {
    /// The widest variant the CPU supports.
    #[default]
    Auto,
    /// The build's target features only (SSE2 in a default x86-64 build).
    Baseline,
    /// AVX2 and FMA (x86-64), if the CPU has them; else the baseline.
    Avx2,
    /// AVX-512F with AVX2 and FMA (x86-64), if the CPU has them; else as [`Simd::Avx2`].
    Avx512,
}

impl Simd {
    /// The variant that runs when `self` is requested on this CPU: never one the CPU
    /// lacks ([`Simd::Auto`] becomes the widest available; an unavailable request falls
    /// back to the next narrower variant).
    pub fn resolve(self) -> Simd {
        let (avx2, avx512) = detected();
        match self {
            Simd::Auto | Simd::Avx512 if avx512 => Simd::Avx512,
            Simd::Auto | Simd::Avx512 | Simd::Avx2 if avx2 => Simd::Avx2,
            _ => Simd::Baseline,
        }
    }

    /// The variants available on this CPU, narrowest first (always starts with
    /// [`Simd::Baseline`]).
    pub fn available() -> Vec<Simd> {
        let (avx2, avx512) = detected();
        let mut v = vec![Simd::Baseline];
        if avx2 {
            v.push(Simd::Avx2);
        }
        if avx512 {
            v.push(Simd::Avx512);
        }
        v
    }
}

/// `(avx2 and fma, avx512f and avx2 and fma)` on this CPU, in a build that compiles those
/// variants (without debug assertions).
#[cfg(all(target_arch = "x86_64", not(debug_assertions)))]
fn detected() -> (bool, bool) {
    let avx2 = std::arch::is_x86_feature_detected!("avx")
        && std::arch::is_x86_feature_detected!("avx2")
        && std::arch::is_x86_feature_detected!("fma");
    (avx2, avx2 && std::arch::is_x86_feature_detected!("avx512f"))
}

#[cfg(not(all(target_arch = "x86_64", not(debug_assertions))))]
fn detected() -> (bool, bool) {
    (false, false)
}
