//! sin and cos of one angle together, for the generated code: its joint angles (through
//! `sin_cos_memo`) and every other angle whose sine and cosine a function needs both (a cam's
//! angle, a roller's contact parameter, a drive's phase).
//!
//! The C library's `sincos` is a call through the dynamic linker that also saves and
//! restores the floating-point environment; in the 16-body chain's right-hand side its 13
//! calls were 7 % of the time (about 15 ns each). This is the FreeBSD msun (fdlibm)
//! algorithm, inlined: the argument reduced by π/2 in the "medium" way of `e_rem_pio2.c`
//! (π/2 in three parts of 33 bits and their tails, enough for every |x| < 1 647 099 rad,
//! just under 2²⁰ π/2) and the kernels of `k_sin.c` and `k_cos.c` (errors below one unit in the
//! last place). Larger or non-finite arguments go to the standard library's `sin_cos`.
//!
//! The results agree with the standard library's to within one unit in the last place
//! (a test compares them on ten million arguments), so generated and numeric dynamics agree
//! as before.

// The coefficients are fdlibm's, printed to 21 digits: each is the nearest double.
#![allow(clippy::excessive_precision)]

/// 2/π.
const INV_PIO2: f64 = std::f64::consts::FRAC_2_PI;
/// The first 33 bits of π/2, and π/2 − PIO2_1.
const PIO2_1: f64 = 1.570_796_326_734_125_614_17;
const PIO2_1T: f64 = 6.077_100_506_506_192_249_32e-11;
/// The next 33 bits, and the rest.
const PIO2_2: f64 = 6.077_100_506_303_965_976_60e-11;
const PIO2_2T: f64 = 2.022_266_248_795_950_631_54e-21;
/// The next 33 bits, and the rest.
const PIO2_3: f64 = 2.022_266_248_711_166_455_80e-21;
const PIO2_3T: f64 = 8.478_427_660_368_899_569_97e-32;
/// The arguments of `e_rem_pio2.c`'s medium case are below this (high word 0x413921fb),
/// just under 2²⁰ π/2.
const MEDIUM: f64 = 1_647_099.0;
/// 2⁻²⁷ (`s_sin.c`'s high word 0x3e400000): below it x³/6 and x²/2 are under half a unit
/// in the last place of sin x and cos x.
const TINY: f64 = 7.450_580_596_923_828e-9;
/// 1.5 · 2⁵²: adding and subtracting it rounds to the nearest integer (ties to even) any
/// number below 2⁵¹ in magnitude.
const TO_INT: f64 = 6_755_399_441_055_744.0;

const S1: f64 = -1.666_666_666_666_663_243_48e-1;
const S2: f64 = 8.333_333_333_322_489_461_24e-3;
const S3: f64 = -1.984_126_982_985_794_931_34e-4;
const S4: f64 = 2.755_731_370_707_006_767_89e-6;
const S5: f64 = -2.505_076_025_340_686_341_95e-8;
const S6: f64 = 1.589_690_995_211_550_102_21e-10;

const C1: f64 = 4.166_666_666_666_660_190_37e-2;
const C2: f64 = -1.388_888_888_887_410_957_49e-3;
const C3: f64 = 2.480_158_728_947_672_941_78e-5;
const C4: f64 = -2.755_731_435_139_066_330_35e-7;
const C5: f64 = 2.087_572_321_298_174_827_90e-9;
const C6: f64 = -1.135_964_755_778_819_482_65e-11;

/// sin(x + y) for |x + y| ≤ π/4, y the tail of the reduced argument (`k_sin.c`).
#[inline(always)]
fn kernel_sin(x: f64, y: f64) -> f64 {
    let z = x * x;
    let w = z * z;
    let r = S2 + z * (S3 + z * S4) + z * w * (S5 + z * S6);
    let v = z * x;
    x - ((z * (0.5 * y - v * r) - y) - v * S1)
}

/// sin x for |x| ≤ π/4: `k_sin.c` without a tail (its `iy = 0` branch, what `s_sin.c`
/// calls there), x + x³ (S1 + x² r): three operations fewer than [`kernel_sin`] with y = 0,
/// which the compiler cannot drop (0 − v r is not −v r for a zero product).
#[inline(always)]
fn kernel_sin_untailed(x: f64) -> f64 {
    let z = x * x;
    let w = z * z;
    let r = S2 + z * (S3 + z * S4) + z * w * (S5 + z * S6);
    let v = z * x;
    x + v * (S1 + z * r)
}

/// cos(x + y) for |x + y| ≤ π/4 (`k_cos.c`).
#[inline(always)]
fn kernel_cos(x: f64, y: f64) -> f64 {
    let z = x * x;
    let w = z * z;
    let r = z * (C1 + z * (C2 + z * C3)) + w * w * (C4 + z * (C5 + z * C6));
    let hz = 0.5 * z;
    let w = 1.0 - hz;
    w + (((1.0 - w) - hz) + (z * r - x * y))
}

/// cos x for |x| ≤ π/4: [`kernel_cos`] with y = 0, bit for bit (z r − x·0 is z r, or a zero
/// that the sum with w ≥ 0.69 does not see), two operations fewer.
#[inline(always)]
fn kernel_cos_untailed(x: f64) -> f64 {
    let z = x * x;
    let w = z * z;
    let r = z * (C1 + z * (C2 + z * C3)) + w * w * (C4 + z * (C5 + z * C6));
    let hz = 0.5 * z;
    let w = 1.0 - hz;
    w + (((1.0 - w) - hz) + z * r)
}

/// The biased exponent of `x`.
#[inline(always)]
fn exponent(x: f64) -> i64 {
    ((x.to_bits() >> 52) & 0x7ff) as i64
}

/// One more round of the reduction of `e_rem_pio2.c`: r − f·part with the rounding error
/// carried in w, for the next part of π/2 and its tail; returns (r, w, r − w).
#[inline(always)]
fn next_round(f: f64, t: f64, part: f64, tail: f64) -> (f64, f64, f64) {
    let w = f * part;
    let r = t - w;
    let w = f * tail - ((t - r) - w);
    (r, w, r - w)
}

/// (sin x, cos x).
#[inline]
pub fn sin_cos(x: f64) -> (f64, f64) {
    let magnitude = x.abs();
    if magnitude <= std::f64::consts::FRAC_PI_4 {
        if magnitude < TINY {
            // s_sin.c and s_cos.c: sin x = x (−0 kept) and cos x = 1, both to rounding.
            return (x, 1.0);
        }
        return (kernel_sin_untailed(x), kernel_cos_untailed(x));
    }
    if magnitude.is_nan() || magnitude >= MEDIUM {
        return x.sin_cos();
    }
    let f = (x * INV_PIO2 + TO_INT) - TO_INT;
    // f is an integer of at most 21 bits: the conversion is exact.
    let quadrant = f as i64;
    let mut r = x - f * PIO2_1; // exact: PIO2_1 has 33 bits, f at most 21
    let mut w = f * PIO2_1T;
    let mut y0 = r - w;
    let j = exponent(x);
    if j - exponent(y0) > 16 {
        // Cancellation: a second round, good to 118 bits.
        (r, w, y0) = next_round(f, r, PIO2_2, PIO2_2T);
        if j - exponent(y0) > 49 {
            // A third, good to 151 bits: every double up to the bound.
            (r, w, y0) = next_round(f, r, PIO2_3, PIO2_3T);
        }
    }
    let y1 = (r - y0) - w;
    let (s, c) = (kernel_sin(y0, y1), kernel_cos(y0, y1));
    match quadrant & 3 {
        0 => (s, c),
        1 => (c, -s),
        2 => (-s, -c),
        _ => (-c, s),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The distance in units in the last place between two doubles of the same sign (or
    /// zero), on the ordered integer line of their bit patterns.
    fn ulps(a: f64, b: f64) -> u64 {
        let key = |x: f64| {
            let bits = x.to_bits() as i64;
            if bits < 0 { i64::MIN - bits } else { bits }
        };
        key(a).abs_diff(key(b))
    }

    /// A small generator (xorshift64*), so that the arguments are reproducible.
    fn uniform(state: &mut u64) -> f64 {
        *state ^= *state >> 12;
        *state ^= *state << 25;
        *state ^= *state >> 27;
        let bits = state.wrapping_mul(0x2545_f491_4f6c_dd1d) >> 11;
        bits as f64 / (1u64 << 53) as f64
    }

    #[test]
    fn agrees_with_the_standard_library_to_one_unit_in_the_last_place() {
        // The C library's sin and cos are correctly rounded on nearly every argument and
        // fdlibm's kernels err by less than one unit, so the two differ by at most one.
        let mut state = 0x9e37_79b9_7f4a_7c15;
        let mut worst = 0;
        for scale in [1.0, 4.0, 30.0, 1e3, 1e5, 1.6e6] {
            for _ in 0..1_000_000 {
                let x = scale * (2.0 * uniform(&mut state) - 1.0);
                let (s, c) = sin_cos(x);
                let (s0, c0) = x.sin_cos();
                worst = worst.max(ulps(s, s0)).max(ulps(c, c0));
                assert!(
                    ulps(s, s0) <= 1 && ulps(c, c0) <= 1,
                    "x = {x:e}: ({s:e}, {c:e}) against ({s0:e}, {c0:e})"
                );
            }
        }
        // Near multiples of π/2, where the reduction cancels most bits.
        for k in 1..200_000i64 {
            let x = k as f64 * std::f64::consts::FRAC_PI_2;
            for x in [
                x,
                f64::from_bits(x.to_bits() + 1),
                f64::from_bits(x.to_bits() - 1),
                -x,
            ] {
                let (s, c) = sin_cos(x);
                let (s0, c0) = x.sin_cos();
                assert!(
                    ulps(s, s0) <= 1 && ulps(c, c0) <= 1,
                    "x = {x:e}: ({s:e}, {c:e}) against ({s0:e}, {c0:e})"
                );
            }
        }
        assert!(worst <= 1);
    }

    #[test]
    fn the_constants_are_fdlibms_to_the_bit() {
        // e_rem_pio2.c, k_sin.c and k_cos.c give each constant's high and low words.
        let words = [
            (INV_PIO2, 0x3FE45F30_6DC9C883_u64),
            (PIO2_1, 0x3FF921FB_54400000),
            (PIO2_1T, 0x3DD0B461_1A626331),
            (PIO2_2, 0x3DD0B461_1A600000),
            (PIO2_2T, 0x3BA3198A_2E037073),
            (PIO2_3, 0x3BA3198A_2E000000),
            (PIO2_3T, 0x397B839A_252049C1),
            (S1, 0xBFC55555_55555549),
            (S2, 0x3F811111_1110F8A6),
            (S3, 0xBF2A01A0_19C161D5),
            (S4, 0x3EC71DE3_57B1FE7D),
            (S5, 0xBE5AE5E6_8A2B9CEB),
            (S6, 0x3DE5D93A_5ACFD57C),
            (C1, 0x3FA55555_5555554C),
            (C2, 0xBF56C16C_16C15177),
            (C3, 0x3EFA01A0_19CB1590),
            (C4, 0xBE927E4F_809C52AD),
            (C5, 0x3E21EE9E_BDB4B1C4),
            (C6, 0xBDA8FAE9_BE8838D4),
        ];
        for (k, (value, bits)) in words.into_iter().enumerate() {
            assert_eq!(value.to_bits(), bits, "constant {k}");
        }
        assert_eq!(MEDIUM.to_bits(), 0x413921FB_00000000);
        assert_eq!(TINY.to_bits(), 0x3E400000_00000000);
    }

    #[test]
    fn small_large_and_special_arguments() {
        assert_eq!(sin_cos(0.0), (0.0, 1.0));
        assert!(sin_cos(-0.0).0.is_sign_negative());
        assert_eq!(sin_cos(1e-300), (1e-300, 1.0));
        // Either side of the tiny bound, and the untailed kernels against the tailed ones
        // (the reduced path's) with a zero tail: the same values to one unit.
        let below = f64::from_bits(TINY.to_bits() - 1);
        for x in [below, TINY, -TINY, 0.3, -0.7, std::f64::consts::FRAC_PI_4] {
            let ((s, c), (s0, c0)) = (sin_cos(x), x.sin_cos());
            assert!(ulps(s, s0) <= 1 && ulps(c, c0) <= 1, "{x:e}");
            assert!(
                ulps(kernel_sin_untailed(x), kernel_sin(x, 0.0)) <= 1,
                "{x:e}"
            );
            assert_eq!(kernel_cos_untailed(x), kernel_cos(x, 0.0), "{x:e}");
        }
        // Either side of the medium case's bound.
        let below = f64::from_bits(MEDIUM.to_bits() - 1);
        for x in [below, -below, MEDIUM, -MEDIUM] {
            let ((s, c), (s0, c0)) = (sin_cos(x), x.sin_cos());
            assert!(ulps(s, s0) <= 1 && ulps(c, c0) <= 1, "{x:e}");
        }
        for x in [1e7, -3e9, 1e300, f64::MAX] {
            assert_eq!(sin_cos(x), x.sin_cos(), "{x:e}");
        }
        for x in [f64::NAN, f64::INFINITY, f64::NEG_INFINITY] {
            let (s, c) = sin_cos(x);
            assert!(s.is_nan() && c.is_nan(), "{x}");
        }
        // The quadrants: exact values where they are exact.
        let (s, c) = sin_cos(std::f64::consts::PI);
        assert!((s - 1.2246467991473532e-16).abs() < 1e-31 && c == -1.0);
    }
}
