//! Run a hot loop compiled for the widest vector instructions the CPU has, chosen at run time.
//!
//! The binary is built for baseline x86-64 (SSE2: two doubles per instruction) so that it runs
//! on any x86-64 machine. A kernel that is worth more wraps its loop in a [`Kernel`] and calls
//! [`widest`] (AVX-512 where present, else AVX2 + FMA) or [`avx2`] (AVX2 + FMA at most); the
//! kernel's `run` is compiled once per level, inside a function that enables that level's
//! instructions, and the level is picked by `is_x86_feature_detected!` (a cached flag).
//!
//! What each level means for the results:
//! - Rust never contracts a·b + c into a fused multiply-add on its own, so a kernel written
//!   with `*` and `+` gives the same bits at every level. A kernel that wants fused
//!   multiply-adds asks its [`Level`] ([`mad`]): one instruction and one rounding at the AVX2
//!   and AVX-512 levels, a multiply then an add at the baseline (where `mul_add` would be a
//!   call to libm's software `fma`, many times slower). Such a kernel's results then differ
//!   between the baseline and the vector levels in the last bits, never between two runs on
//!   one machine.
//! - The levels differ in vector width: AVX2 holds 4 doubles (8 floats), AVX-512 8 (16). On
//!   AMD Zen 4 a 512-bit instruction takes two cycles, so AVX-512 pays where a loop is bound by
//!   latency (more wavelengths in flight per instruction: the double-precision water kernel
//!   went from 289 k to 446 k evaluations/s, 1.54×, with nothing else changed, in a harness
//!   during issue 18's ninth round) and not where it is bound by throughput (the aLMI lanes
//!   measured 0–3 % slower, the exact correction no different, so they ask for [`avx2`]).
//!
//! The one `unsafe` block of each level is here, with its safety argument.

/// A loop to compile per instruction-set level. `run` must be `#[inline(always)]` (so that its
/// body, and the `#[inline(always)]` functions it calls, are compiled inside the level's
/// function rather than called from it at the baseline level).
pub trait Kernel {
    /// What the loop returns.
    type Output;
    /// The loop, compiled for level `L`.
    fn run<L: Level>(self) -> Self::Output;
}

/// What an instruction-set level offers a kernel.
pub trait Level {
    /// a·b + c is one instruction (FMA).
    const FMA: bool;
}

/// The baseline (SSE2 on x86-64): no FMA.
pub struct Baseline;
/// AVX2 with FMA.
pub struct Avx2;
/// AVX-512 (F and VL) with AVX2 and FMA.
pub struct Avx512;

impl Level for Baseline {
    const FMA: bool = false;
}
impl Level for Avx2 {
    const FMA: bool = true;
}
impl Level for Avx512 {
    const FMA: bool = true;
}

/// a·b + c at level `L`: fused (one rounding) where `L` has FMA, else a multiply then an add.
#[inline(always)]
pub fn mad<L: Level, T: MulAdd>(a: T, b: T, c: T) -> T {
    if L::FMA { a.fused(b, c) } else { a.unfused(b, c) }
}

/// The float types [`mad`] takes.
pub trait MulAdd: Copy {
    /// a·b + c with one rounding.
    fn fused(self, b: Self, c: Self) -> Self;
    /// a·b + c with two.
    fn unfused(self, b: Self, c: Self) -> Self;
}

impl MulAdd for f64 {
    #[inline(always)]
    fn fused(self, b: Self, c: Self) -> Self {
        self.mul_add(b, c)
    }
    #[inline(always)]
    fn unfused(self, b: Self, c: Self) -> Self {
        self * b + c
    }
}

impl MulAdd for f32 {
    #[inline(always)]
    fn fused(self, b: Self, c: Self) -> Self {
        self.mul_add(b, c)
    }
    #[inline(always)]
    fn unfused(self, b: Self, c: Self) -> Self {
        self * b + c
    }
}

/// The instruction-set level this CPU runs `widest` at: "AVX-512", "AVX2+FMA" or "portable"
/// (for `shoal bench` to print).
#[must_use]
pub fn widest_level() -> &'static str {
    #[cfg(target_arch = "x86_64")]
    {
        if x86::avx512_available() {
            return "AVX-512";
        }
        if x86::avx2_available() {
            return "AVX2+FMA";
        }
    }
    "portable"
}

/// Run `kernel` at the widest level the CPU has: AVX-512 (F and VL) with AVX2 and FMA, or AVX2
/// with FMA, or the baseline.
#[inline]
pub fn widest<K: Kernel>(kernel: K) -> K::Output {
    #[cfg(target_arch = "x86_64")]
    {
        if x86::avx512_available() {
            return x86::avx512(kernel);
        }
        if x86::avx2_available() {
            return x86::avx2(kernel);
        }
    }
    kernel.run::<Baseline>()
}

/// Run `kernel` with AVX2 and FMA where the CPU has them (even if it has AVX-512), else at the
/// baseline.
#[inline]
pub fn avx2<K: Kernel>(kernel: K) -> K::Output {
    #[cfg(target_arch = "x86_64")]
    if x86::avx2_available() {
        return x86::avx2(kernel);
    }
    kernel.run::<Baseline>()
}

#[cfg(target_arch = "x86_64")]
mod x86 {
    use super::{Avx2, Avx512, Kernel};

    pub fn avx512_available() -> bool {
        std::is_x86_feature_detected!("avx512f") && std::is_x86_feature_detected!("avx512vl") && avx2_available()
    }

    pub fn avx2_available() -> bool {
        std::is_x86_feature_detected!("avx2") && std::is_x86_feature_detected!("fma")
    }

    #[target_feature(enable = "avx512f,avx512vl,avx2,fma")]
    fn avx512_body<K: Kernel>(kernel: K) -> K::Output {
        kernel.run::<Avx512>()
    }

    #[target_feature(enable = "avx2,fma")]
    fn avx2_body<K: Kernel>(kernel: K) -> K::Output {
        kernel.run::<Avx2>()
    }

    pub fn avx512<K: Kernel>(kernel: K) -> K::Output {
        debug_assert!(avx512_available());
        // SAFETY: the only caller checks `avx512_available()`: the CPU executes AVX-512F,
        // AVX-512VL, AVX2 and FMA instructions.
        #[allow(unsafe_code)]
        unsafe {
            avx512_body(kernel)
        }
    }

    pub fn avx2<K: Kernel>(kernel: K) -> K::Output {
        debug_assert!(avx2_available());
        // SAFETY: the callers check `avx2_available()`: the CPU executes AVX2 and FMA.
        #[allow(unsafe_code)]
        unsafe {
            avx2_body(kernel)
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A sum: with `mad`, fused at the vector levels only.
    struct Dot<'a>(&'a [f64], &'a [f64]);

    impl Kernel for Dot<'_> {
        type Output = f64;
        #[inline(always)]
        fn run<L: Level>(self) -> f64 {
            self.0.iter().zip(self.1).fold(0.0, |s, (a, b)| mad::<L, f64>(*a, *b, s))
        }
    }

    #[test]
    fn each_level_fuses_as_it_says() {
        let a: Vec<f64> = (0..1001).map(|i| (f64::from(i) * 0.37).sin()).collect();
        let b: Vec<f64> = (0..1001).map(|i| (f64::from(i) * 0.11).cos()).collect();
        let base = Dot(&a, &b).run::<Baseline>();
        let fused = Dot(&a, &b).run::<Avx2>();
        assert_eq!(base.to_bits(), a.iter().zip(&b).fold(0.0, |s, (a, b)| a * b + s).to_bits());
        assert_eq!(fused.to_bits(), a.iter().zip(&b).fold(0.0, |s, (a, b)| a.mul_add(*b, s)).to_bits());
        let want = match widest_level() {
            "portable" => base,
            _ => fused,
        };
        assert_eq!(widest(Dot(&a, &b)).to_bits(), want.to_bits());
        assert_eq!(avx2(Dot(&a, &b)).to_bits(), want.to_bits());
    }
}
