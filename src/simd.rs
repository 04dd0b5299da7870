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
//!   latency (more wavelengths in flight per instruction: the double-precision water kernel) and
//!   not where it is bound by throughput. AMD Zen 5 runs them in one, so the throughput-bound
//!   kernels that gained from it there (the band model's nodes, the exact correction) ask for
//!   [`throughput`]: AVX-512 on such a CPU, AVX2 elsewhere. Those that did not (the aLMI lanes,
//!   25 % slower at AVX-512 on Zen 5; the radiance stage's node sums, no faster) ask for
//!   [`avx2`]. `SHOAL_SIMD=… shoal bench` measures each level (docs/RESULTS.md).
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

/// The environment variable that caps the level every kernel runs at: `baseline`, `avx2` or
/// `avx512` (unset: no cap). With it, one machine measures what a CPU without AVX-512 or
/// without AVX2 would (`SHOAL_SIMD=baseline shoal bench`), and the levels' results can be
/// compared. Any other value is refused by the binary at start ([`check_env`]).
pub const CAP_ENV: &str = "SHOAL_SIMD";

/// An instruction-set tier, ordered: what a CPU has, and what [`CAP_ENV`] allows.
#[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord)]
pub enum Tier {
    /// The baseline (SSE2 on x86-64).
    Baseline,
    /// AVX2 with FMA.
    Avx2,
    /// AVX-512 (F and VL) with AVX2 and FMA.
    Avx512,
}

impl Tier {
    /// The cap a value of [`CAP_ENV`] asks for (`None` or empty, unset: no cap).
    ///
    /// # Errors
    /// A value other than `baseline`, `avx2` and `avx512`, with the variable and the values
    /// allowed named.
    pub fn parse_cap(value: Option<&str>) -> Result<Self, String> {
        match value.map(str::trim) {
            None | Some("" | "avx512") => Ok(Self::Avx512),
            Some("avx2") => Ok(Self::Avx2),
            Some("baseline") => Ok(Self::Baseline),
            Some(other) => {
                Err(format!("{CAP_ENV}={other:?}: allowed values are baseline, avx2 and avx512 (or leave it unset)"))
            }
        }
    }

    /// The highest tier this CPU has.
    fn of_cpu() -> Self {
        #[cfg(target_arch = "x86_64")]
        {
            if x86::avx512_available() {
                return Self::Avx512;
            }
            if x86::avx2_available() {
                return Self::Avx2;
            }
        }
        Self::Baseline
    }
}

/// The tier the kernels run at: the CPU's, at most the cap read from [`CAP_ENV`] (once; a value
/// the binary refuses at start, see [`check_env`], caps nothing).
fn tier() -> Tier {
    static TIER: std::sync::OnceLock<Tier> = std::sync::OnceLock::new();
    let tier = *TIER.get_or_init(|| {
        let cap = Tier::parse_cap(std::env::var(CAP_ENV).ok().as_deref()).unwrap_or(Tier::Avx512);
        Tier::of_cpu().min(cap)
    });
    #[cfg(test)]
    if let Some(cap) = TEST_CAP.get() {
        return tier.min(cap);
    }
    tier
}

#[cfg(test)]
thread_local! {
    static TEST_CAP: std::cell::Cell<Option<Tier>> = const { std::cell::Cell::new(None) };
}

/// Run `f` with every kernel this thread runs capped at `cap` (tests compare the levels' bits
/// within one process, where [`CAP_ENV`] is read once).
#[cfg(test)]
pub(crate) fn capped<R>(cap: Tier, f: impl FnOnce() -> R) -> R {
    TEST_CAP.set(Some(cap));
    let out = f();
    TEST_CAP.set(None);
    out
}

/// Check [`CAP_ENV`].
///
/// # Errors
/// Its value is not one of those allowed (the message names them).
pub fn check_env() -> Result<(), String> {
    Tier::parse_cap(std::env::var(CAP_ENV).ok().as_deref()).map(|_| ())
}

/// The instruction-set level this CPU runs `widest` at: "AVX-512", "AVX2+FMA" or "portable"
/// (for `shoal bench` to print), saying at which the throughput-bound kernels run on an AVX-512
/// CPU ([`throughput`]), with "(capped by SHOAL_SIMD)" when [`CAP_ENV`] lowered it.
#[must_use]
pub fn widest_level() -> String {
    let name = match tier() {
        Tier::Avx512 if throughput_at_512() => "AVX-512 (512 bits at full width)",
        Tier::Avx512 => "AVX-512 (throughput-bound kernels at AVX2)",
        Tier::Avx2 => "AVX2+FMA",
        Tier::Baseline => "portable",
    };
    if tier() < Tier::of_cpu() { format!("{name} (capped by {CAP_ENV})") } else { name.into() }
}

/// Run `kernel` at the widest level the CPU has: AVX-512 (F and VL) with AVX2 and FMA, or AVX2
/// with FMA, or the baseline (at most the level [`CAP_ENV`] allows).
#[inline]
pub fn widest<K: Kernel>(kernel: K) -> K::Output {
    match tier() {
        #[cfg(target_arch = "x86_64")]
        Tier::Avx512 => x86::avx512(kernel),
        #[cfg(target_arch = "x86_64")]
        Tier::Avx2 => x86::avx2(kernel),
        _ => kernel.run::<Baseline>(),
    }
}

/// Run a throughput-bound `kernel` at AVX-512 where the CPU executes 512-bit instructions at
/// full width (AMD Zen 5 and later: [`full_width_512`]), else as [`avx2`] runs it (at most the
/// level [`CAP_ENV`] allows). On AMD Zen 4 a 512-bit instruction takes two cycles, so such a
/// kernel gains nothing from it (the aLMI lanes measured 0–3 % slower); on Zen 5 each takes one
/// (the SAMBUCA-style fit of 28 bands 1.33× as fast as at AVX2, the exact correction 1.1×).
#[inline]
pub fn throughput<K: Kernel>(kernel: K) -> K::Output {
    #[cfg(target_arch = "x86_64")]
    if throughput_at_512() {
        return x86::avx512(kernel);
    }
    avx2(kernel)
}

/// Whether [`throughput`] runs its kernels at AVX-512: the level allows it and the CPU runs
/// 512-bit instructions at full width (what the dispatch, the padding of
/// [`throughput_f64_lanes`] and [`widest_level`] all read).
fn throughput_at_512() -> bool {
    tier() == Tier::Avx512 && full_width_512()
}

/// Whether the CPU's 512-bit instructions run at full width: AMD family 1Ah (Zen 5) and later.
/// Other CPUs with AVX-512 (AMD Zen 4, family 19h, whose units are 256 bits wide; Intel's, not
/// measured here) answer no. Read once from CPUID (vendor, leaf 0; family, leaf 1, as AMD's
/// "CPUID Specification" 25481 §E.3.2 composes it: base family, plus the extended family where
/// the base is Fh).
#[must_use]
pub fn full_width_512() -> bool {
    static FULL: std::sync::OnceLock<bool> = std::sync::OnceLock::new();
    *FULL.get_or_init(|| {
        #[cfg(target_arch = "x86_64")]
        {
            let (vendor, signature) = x86::vendor_and_signature();
            vendor == *b"AuthenticAMD" && family(signature) >= 0x1A
        }
        #[cfg(not(target_arch = "x86_64"))]
        false
    })
}

/// Doubles per vector instruction of a kernel run by [`throughput`]: 8 at AVX-512, 4 otherwise
/// (what a kernel pads its loops to, so that they run whole vectors).
#[must_use]
pub fn throughput_f64_lanes() -> usize {
    if throughput_at_512() { 8 } else { 4 }
}

/// The family of a CPUID leaf 1 signature (EAX): bits 8–11, plus bits 20–27 where those are Fh.
fn family(signature: u32) -> u32 {
    let base = (signature >> 8) & 0xF;
    if base == 0xF { base + ((signature >> 20) & 0xFF) } else { base }
}

/// Run `kernel` with AVX2 and FMA where the CPU has them (even if it has AVX-512), else at the
/// baseline (at most the level [`CAP_ENV`] allows).
#[inline]
pub fn avx2<K: Kernel>(kernel: K) -> K::Output {
    match tier() {
        #[cfg(target_arch = "x86_64")]
        Tier::Avx512 | Tier::Avx2 => x86::avx2(kernel),
        _ => kernel.run::<Baseline>(),
    }
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

    /// The vendor string (CPUID leaf 0: EBX, EDX, ECX) and the leaf 1 signature (EAX).
    pub fn vendor_and_signature() -> ([u8; 12], u32) {
        // SAFETY: CPUID leaves 0 and 1 exist on every x86-64 CPU and only read registers.
        #[allow(unsafe_code, unused_unsafe)]
        let (zero, one) = unsafe { (std::arch::x86_64::__cpuid(0), std::arch::x86_64::__cpuid(1)) };
        let mut vendor = [0; 12];
        for (chunk, word) in vendor.chunks_mut(4).zip([zero.ebx, zero.edx, zero.ecx]) {
            chunk.copy_from_slice(&word.to_le_bytes());
        }
        (vendor, one.eax)
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
        let want = if widest_level().starts_with("portable") { base } else { fused };
        assert_eq!(widest(Dot(&a, &b)).to_bits(), want.to_bits());
        assert_eq!(avx2(Dot(&a, &b)).to_bits(), want.to_bits());
        assert_eq!(throughput(Dot(&a, &b)).to_bits(), want.to_bits());
    }

    #[test]
    fn the_family_adds_the_extended_family_only_to_family_f() {
        // Signatures of AMD Zen 3 (19h, model 01h), Zen 5 (1Ah) and an Intel Core (6, model 55h).
        assert_eq!(family(0x00A0_0F11), 0x19);
        assert_eq!(family(0x00B0_0F21), 0x1A);
        assert_eq!(family(0x0005_0654), 6);
    }

    #[test]
    fn the_cap_takes_the_three_levels_and_refuses_anything_else_by_name() {
        assert_eq!(Tier::parse_cap(None), Ok(Tier::Avx512));
        assert_eq!(Tier::parse_cap(Some("")), Ok(Tier::Avx512));
        assert_eq!(Tier::parse_cap(Some("avx512")), Ok(Tier::Avx512));
        assert_eq!(Tier::parse_cap(Some(" avx2 ")), Ok(Tier::Avx2));
        assert_eq!(Tier::parse_cap(Some("baseline")), Ok(Tier::Baseline));
        let e = Tier::parse_cap(Some("sse9")).unwrap_err();
        assert!(e.contains("SHOAL_SIMD") && e.contains("baseline, avx2 and avx512"), "{e}");
        assert!(Tier::Baseline < Tier::Avx2 && Tier::Avx2 < Tier::Avx512);
    }
}
