//! The instruction sets that the renderer's vector kernels (the small
//! scene's ray tests, the light terms' lanes) are compiled for, each kernel
//! once per set, and the processor's best, chosen when it runs. The
//! arithmetic is the same in each (Rust never fuses a multiply and an add
//! on its own), so the answers are the same bit for bit. The default build
//! targets x86-64's baseline, which runs on every x86-64 processor.

/// An instruction set a kernel is compiled for.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
#[cfg_attr(not(target_arch = "x86_64"), allow(dead_code))]
pub(crate) enum Isa {
    #[default]
    Baseline,
    /// AVX2 and FMA.
    Avx2,
    /// AVX-512 F, VL, DQ and BW, with AVX2 and FMA.
    Avx512,
}

impl Isa {
    /// The best this processor has.
    pub fn best() -> Isa {
        #[cfg(target_arch = "x86_64")]
        {
            use std::arch::is_x86_feature_detected as has;
            if has!("avx2") && has!("fma") {
                if has!("avx512f") && has!("avx512vl") && has!("avx512dq") && has!("avx512bw") {
                    return Isa::Avx512;
                }
                return Isa::Avx2;
            }
        }
        Isa::Baseline
    }

    /// Every instruction set this processor runs, for tests that check
    /// each kernel against the baseline; the sets it lacks are named as
    /// skipped, so that a pass on an older processor says what it left out.
    #[cfg(test)]
    pub fn available() -> Vec<Isa> {
        let isas = Self::runnable();
        for isa in [Isa::Avx2, Isa::Avx512] {
            if !isas.contains(&isa) {
                eprintln!("skipped: the {isa:?} kernels (this processor does not run them)");
            }
        }
        isas
    }

    #[cfg(test)]
    fn runnable() -> Vec<Isa> {
        let mut isas = vec![Isa::Baseline];
        #[cfg(target_arch = "x86_64")]
        {
            use std::arch::is_x86_feature_detected as has;
            if has!("avx2") && has!("fma") {
                isas.push(Isa::Avx2);
            }
        }
        if Isa::best() == Isa::Avx512 {
            isas.push(Isa::Avx512);
        }
        isas
    }
}
