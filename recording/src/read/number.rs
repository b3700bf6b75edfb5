//! Plain decimals converted while the range parser scans them: eight digits at a time
//! (SWAR) with Clinger's exact fast path, so the value is the correctly rounded one.

const POW10: [f64; 23] = [
    1e0, 1e1, 1e2, 1e3, 1e4, 1e5, 1e6, 1e7, 1e8, 1e9, 1e10, 1e11, 1e12, 1e13, 1e14, 1e15, 1e16,
    1e17, 1e18, 1e19, 1e20, 1e21, 1e22,
];

/// A short plain decimal (`-12.345`, no exponent) converted while it is scanned, eight
/// digits at a time (SWAR), with Clinger's exact fast path (see `csvread::parse_f64`):
/// the result is the correctly rounded value. `None` for anything else (an exponent, more
/// than eight digits on either side of the point, a leading `+`), which the caller hands
/// to `parse_f64`. Returns the value and the offset after it.
#[inline(always)]
pub(super) fn number(buf: &[u8], i: usize) -> Option<(f64, usize)> {
    // The sign without a branch: it is random in noise.
    let neg = usize::from(buf.get(i) == Some(&b'-'));
    let mut i = i + neg;
    let x = load8(buf, i);
    let n_int = digits(x);
    if n_int == 8 {
        return None;
    }
    let mut mant = eight(x, n_int);
    i += n_int;
    let mut frac = 0;
    if buf.get(i) == Some(&b'.') {
        i += 1;
        let x = load8(buf, i);
        frac = digits(x);
        if frac == 8 {
            return None;
        }
        mant = mant * POW10U[frac] + eight(x, frac);
        i += frac;
    }
    if n_int + frac == 0 {
        return None;
    }
    match buf.get(i) {
        None | Some(b',') | Some(b'\n') | Some(b'\r') => {}
        _ => return None,
    }
    // Both parts have at most 7 digits: the mantissa is below 10^14 < 2^53, exact.
    let v = mant as f64 / POW10[frac];
    Some((f64::from_bits(v.to_bits() | (neg as u64) << 63), i))
}

const POW10U: [u64; 8] = [1, 10, 100, 1000, 10_000, 100_000, 1_000_000, 10_000_000];

/// Eight bytes from `buf[i..]`, the first in the lowest byte, zero-padded past the end.
#[inline(always)]
fn load8(buf: &[u8], i: usize) -> u64 {
    match buf.get(i..i + 8) {
        Some(b) => u64::from_le_bytes(b.try_into().expect("eight bytes")),
        None => {
            let mut a = [0u8; 8];
            let rest = buf.get(i..).unwrap_or(&[]);
            a[..rest.len()].copy_from_slice(rest);
            u64::from_le_bytes(a)
        }
    }
}

/// How many of the eight bytes, from the lowest, are ASCII digits.
#[inline(always)]
fn digits(x: u64) -> usize {
    const ONES: u64 = 0x0101_0101_0101_0101;
    let d = x ^ (0x30 * ONES); // digits become 0..=9
    // High bit of a byte set when it is not a digit; a carry out of a non-digit byte can
    // only disturb later bytes, past the first non-digit.
    let flags = (d.wrapping_add(0x76 * ONES) | d) & (0x80 * ONES);
    (flags.trailing_zeros() / 8) as usize
}

/// The value of the first `n` (< 8) digit bytes of `x`.
#[inline(always)]
fn eight(x: u64, n: usize) -> u64 {
    if n == 0 {
        return 0;
    }
    // Move the n digits to the top (most significant digits become leading zeros below).
    let mut v = (x & 0x0F0F_0F0F_0F0F_0F0F) << (8 * (8 - n));
    v = (v.wrapping_mul(2561)) >> 8;
    v = ((v & 0x00FF_00FF_00FF_00FF).wrapping_mul(6_553_601)) >> 16;
    ((v & 0x0000_FFFF_0000_FFFF).wrapping_mul(42_949_672_960_001)) >> 32
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn inline_numbers_match_std() {
        for s in [
            "0",
            "-0.013975",
            "9.788327",
            "22.000",
            "1234567.1234567",
            "-0.0",
            "-100.0",
            "0.1",
            "0.0000001",
            "17",
            ".5",
            "5.",
        ] {
            let want: f64 = s.parse().unwrap();
            let (v, end) = number(s.as_bytes(), 0).unwrap();
            assert_eq!((v.to_bits(), end), (want.to_bits(), s.len()), "{s}");
        }
        // Not for the inline path: the caller falls back to `parse_f64`.
        for s in [
            "1e3",
            "-",
            "",
            ".",
            "+1",
            "12345678.5",
            "1.12345678",
            "1.2.3",
            "--1",
            "1x",
        ] {
            assert!(number(s.as_bytes(), 0).is_none(), "{s}");
        }
    }

    proptest::proptest! {
        /// Any decimal with up to 7 digits each side, in a row between other cells,
        /// converts to exactly what `str::parse` gives.
        #[test]
        fn swar_digits_match_std(int in 0u64..10_000_000, fr in 0u64..10_000_000,
                                 nf in 0usize..8, neg: bool, lead in 0usize..3) {
            let f = format!("{fr:07}");
            let text = format!(
                "{}{}{}.{}",
                if neg { "-" } else { "" },
                "0".repeat(lead),
                int,
                &f[..nf]
            );
            let n_int = text.trim_start_matches('-').split('.').next().unwrap().len();
            let row = format!("{text},1\n");
            let want: f64 = text.parse().unwrap();
            match number(row.as_bytes(), 0) {
                Some((v, end)) => {
                    proptest::prop_assert_eq!(v.to_bits(), want.to_bits(), "{}", text);
                    proptest::prop_assert_eq!(end, text.len());
                }
                None => proptest::prop_assert!(n_int >= 8, "{} refused", text),
            }
        }
    }
}
