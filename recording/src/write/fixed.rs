//! Fixed-decimal number formatting for the CSV streams: exactly the decimals each column
//! needs, built on the stack, no allocation (the hot path of a 1 kHz recording).

/// Appends `x` with exactly `dec` (<= 12) decimals (rounded half away from zero); non-finite values
/// are written `NaN`, `inf`, `-inf` (so that a reader refuses them, naming the cell).
pub fn push_fixed(buf: &mut Vec<u8>, x: f64, dec: u32) {
    let mut l = Line::new();
    match dec {
        0 => l.fixed::<0>(x),
        1 => l.fixed::<1>(x),
        2 => l.fixed::<2>(x),
        3 => l.fixed::<3>(x),
        4 => l.fixed::<4>(x),
        5 => l.fixed::<5>(x),
        6 => l.fixed::<6>(x),
        7 => l.fixed::<7>(x),
        8 => l.fixed::<8>(x),
        9 => l.fixed::<9>(x),
        10 => l.fixed::<10>(x),
        11 => l.fixed::<11>(x),
        _ => l.fixed::<12>(x),
    }
    buf.extend_from_slice(l.as_bytes());
}

/// Powers of ten.
const P10: [u64; 20] = {
    let mut p = [1u64; 20];
    let mut i = 1;
    while i < 20 {
        p[i] = p[i - 1] * 10;
        i += 1;
    }
    p
};

/// `"00".."99"`, two digits at a time.
const PAIRS: [u8; 200] = {
    let mut t = [0u8; 200];
    let mut i = 0;
    while i < 100 {
        t[2 * i] = b'0' + (i / 10) as u8;
        t[2 * i + 1] = b'0' + (i % 10) as u8;
        i += 1;
    }
    t
};

/// One CSV row built on the stack (the hot path of a 1 kHz recording: no allocation, one
/// copy per row).
pub(crate) struct Line {
    buf: [u8; 320],
    len: usize,
}

impl Line {
    pub(crate) fn new() -> Self {
        Line {
            buf: [0; 320],
            len: 0,
        }
    }

    pub(crate) fn as_bytes(&self) -> &[u8] {
        &self.buf[..self.len]
    }

    pub(crate) fn byte(&mut self, b: u8) {
        self.buf[self.len] = b;
        self.len += 1;
    }

    fn bytes(&mut self, s: &[u8]) {
        for &b in s {
            self.byte(b);
        }
    }

    /// Appends `x` in its shortest form that reads back to the same `f64` (ryu): values
    /// copied from another system's file, kept exactly.
    pub(crate) fn shortest(&mut self, x: f64) {
        if !x.is_finite() {
            self.fixed::<0>(x);
            return;
        }
        let mut rb = ryu::Buffer::new();
        let s = rb.format_finite(x);
        let s = s.strip_suffix(".0").unwrap_or(s);
        self.bytes(s.as_bytes());
    }

    /// Appends `x` with exactly `DEC` (<= 12) decimals; `DEC` is a constant so that the
    /// divisions below compile to multiplications.
    #[inline(always)]
    pub(crate) fn fixed<const DEC: usize>(&mut self, x: f64) {
        if !x.is_finite() {
            self.bytes(if x.is_nan() {
                b"NaN"
            } else if x > 0.0 {
                b"inf"
            } else {
                b"-inf"
            });
            return;
        }
        let scale = P10[DEC];
        let r = x * scale as f64;
        if r.abs() >= 9.0e18 {
            // Beyond u64: the shortest exact representation.
            let mut rb = ryu::Buffer::new();
            let s = rb.format_finite(x).as_bytes().to_owned();
            self.bytes(&s);
            return;
        }
        let n = (r.abs() + 0.5) as u64;
        if r < 0.0 && n != 0 {
            self.byte(b'-');
        }
        let (mut int, mut frac) = (n / scale, n % scale);
        // Integer part, right to left into a scratch area, then copied.
        let mut tmp = [0u8; 20];
        let mut pos = 20;
        while int >= 100 {
            let d = (int % 100) as usize;
            int /= 100;
            tmp[pos - 2..pos].copy_from_slice(&PAIRS[2 * d..2 * d + 2]);
            pos -= 2;
        }
        if int >= 10 {
            let d = int as usize;
            tmp[pos - 2..pos].copy_from_slice(&PAIRS[2 * d..2 * d + 2]);
            pos -= 2;
        } else {
            pos -= 1;
            tmp[pos] = b'0' + int as u8;
        }
        let k = 20 - pos;
        self.buf[self.len..self.len + k].copy_from_slice(&tmp[pos..]);
        self.len += k;
        if DEC == 0 {
            return;
        }
        self.byte(b'.');
        // Exactly DEC fractional digits.
        let end = self.len + DEC;
        let mut p = end;
        let mut left = DEC;
        while left >= 2 {
            let d = (frac % 100) as usize;
            frac /= 100;
            self.buf[p - 2..p].copy_from_slice(&PAIRS[2 * d..2 * d + 2]);
            p -= 2;
            left -= 2;
        }
        if left == 1 {
            self.buf[p - 1] = b'0' + (frac % 10) as u8;
        }
        self.len = end;
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn fixed(x: f64, dec: u32) -> String {
        let mut b = Vec::new();
        push_fixed(&mut b, x, dec);
        String::from_utf8(b).unwrap()
    }

    #[test]
    fn fixed_matches_std_formatting() {
        for &x in &[
            0.0,
            1.5,
            -0.25,
            9.80665,
            -123.456789012,
            1e-7,
            -4e-7,
            5700.000001,
            359.9999999,
        ] {
            for dec in [0u32, 4, 6, 7] {
                let text = fixed(x, dec);
                let ours: f64 = text.parse().unwrap();
                // Rounded to the nearest step (ties may go either way), with exactly `dec` decimals.
                assert!(
                    (ours - x).abs() <= 0.5 * 10f64.powi(-(dec as i32)) * (1.0 + 1e-9),
                    "{x} {dec}: {text}"
                );
                assert_eq!(text.split('.').nth(1).map_or(0, str::len), dec as usize);
            }
        }
        assert_eq!(fixed(-0.0000001, 6), "0.000000");
        assert_eq!(fixed(f64::NAN, 6), "NaN");
        assert_eq!(fixed(-12.5, 0), "-13");
        assert_eq!(fixed(0.05, 1), "0.1");
        assert_eq!(fixed(-0.001234, 7), "-0.0012340");
        assert_eq!(fixed(123456.789, 2), "123456.79");
        assert_eq!(fixed(9.0, 6), "9.000000");
        assert_eq!(fixed(1e300, 6), "1e300");
    }

    #[test]
    fn shortest_reads_back_exactly() {
        let short = |x: f64| {
            let mut l = Line::new();
            l.shortest(x);
            String::from_utf8(l.as_bytes().to_vec()).unwrap()
        };
        assert_eq!(short(1.0), "1");
        assert_eq!(short(-0.25), "-0.25");
        assert_eq!(short(f64::NAN), "NaN");
        for x in [
            10.332114257812501,
            0.1 + 0.2,
            1e-7,
            -4.4e-17,
            5700.000001,
            1e300,
        ] {
            assert_eq!(short(x).parse::<f64>().unwrap(), x, "{x}");
        }
    }
}
