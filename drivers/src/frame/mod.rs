//! The binary IMU frame of `docs/protocols.md`: sync bytes, payload length, sample counter,
//! device time stamp, six channels, temperature, status flags and a CRC-16. Frames are read
//! in place from the receive buffer ([`Frame`] borrows its bytes) and skipped, counted, when
//! their CRC or length is wrong.

mod reader;

pub use reader::FrameReader;

/// The two bytes that start every frame.
pub const SYNC: [u8; 2] = [0xA5, 0x5A];
/// Payload length: counter (4), device time (8), six channels and temperature (7 x 8),
/// flags (2).
pub const PAYLOAD_LEN: usize = 4 + 8 + 7 * 8 + 2;
/// Whole frame: sync (2), length (1), payload, CRC (2).
pub const FRAME_LEN: usize = 3 + PAYLOAD_LEN + 2;
/// Flag: an accelerometer channel is at the end of its range.
pub const FLAG_ACCEL_SATURATED: u16 = 1;
/// Flag: a gyro channel is at the end of its range.
pub const FLAG_GYRO_SATURATED: u16 = 2;

/// CRC-16/IBM-3740 (CCITT-FALSE: poly 0x1021, init 0xFFFF) over the length byte and the
/// payload, sent little-endian.
pub const CRC: crc::Crc<u16> = crc::Crc::<u16>::new(&crc::CRC_16_IBM_3740);

/// The values of one frame, for encoding.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct FrameFields {
    /// Sample counter (wraps at 2^32).
    pub counter: u32,
    /// Device time stamp, ns since the device started.
    pub time_ns: u64,
    /// Accelerometer outputs, m/s^2.
    pub accel: [f64; 3],
    /// Gyro outputs, deg/s.
    pub gyro: [f64; 3],
    /// Internal temperature, degC (NaN: not measured).
    pub temp_c: f64,
    /// Status flags (`FLAG_*`).
    pub flags: u16,
}

/// Appends the encoded frame to `out`.
pub fn encode(f: &FrameFields, out: &mut Vec<u8>) {
    let start = out.len();
    out.extend_from_slice(&SYNC);
    out.push(PAYLOAD_LEN as u8);
    out.extend_from_slice(&f.counter.to_le_bytes());
    out.extend_from_slice(&f.time_ns.to_le_bytes());
    for v in f.accel.iter().chain(&f.gyro).chain([&f.temp_c]) {
        out.extend_from_slice(&v.to_le_bytes());
    }
    out.extend_from_slice(&f.flags.to_le_bytes());
    let crc = CRC.checksum(&out[start + 2..]);
    out.extend_from_slice(&crc.to_le_bytes());
}

/// A checked frame, read in place: accessors decode fields from the borrowed payload.
#[derive(Debug, Clone, Copy)]
pub struct Frame<'a>(&'a [u8]);

impl<'a> Frame<'a> {
    /// Checks a whole frame (`FRAME_LEN` bytes starting at the sync bytes).
    pub fn check(bytes: &'a [u8]) -> Option<Frame<'a>> {
        if bytes.len() != FRAME_LEN || bytes[..2] != SYNC || bytes[2] as usize != PAYLOAD_LEN {
            return None;
        }
        let (body, crc) = bytes.split_at(FRAME_LEN - 2);
        let sent = u16::from_le_bytes([crc[0], crc[1]]);
        (CRC.checksum(&body[2..]) == sent).then(|| Frame(&body[3..]))
    }

    fn f64_at(&self, i: usize) -> f64 {
        let o = 12 + 8 * i;
        f64::from_le_bytes(self.0[o..o + 8].try_into().expect("8 bytes"))
    }

    /// Sample counter.
    pub fn counter(&self) -> u32 {
        u32::from_le_bytes(self.0[..4].try_into().expect("4 bytes"))
    }

    /// Device time stamp, ns.
    pub fn time_ns(&self) -> u64 {
        u64::from_le_bytes(self.0[4..12].try_into().expect("8 bytes"))
    }

    /// Accelerometer outputs, m/s^2.
    pub fn accel(&self) -> [f64; 3] {
        [self.f64_at(0), self.f64_at(1), self.f64_at(2)]
    }

    /// Gyro outputs, deg/s.
    pub fn gyro(&self) -> [f64; 3] {
        [self.f64_at(3), self.f64_at(4), self.f64_at(5)]
    }

    /// Internal temperature, degC, if measured.
    pub fn temp_c(&self) -> Option<f64> {
        Some(self.f64_at(6)).filter(|t| !t.is_nan())
    }

    /// Status flags.
    pub fn flags(&self) -> u16 {
        u16::from_le_bytes([self.0[PAYLOAD_LEN - 2], self.0[PAYLOAD_LEN - 1]])
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn fields(counter: u32) -> FrameFields {
        FrameFields {
            counter,
            time_ns: 1_000_000 * u64::from(counter),
            accel: [0.1, -0.2, 9.81],
            gyro: [0.01, 100.0, -3.5],
            temp_c: 25.5,
            flags: FLAG_GYRO_SATURATED,
        }
    }

    #[test]
    fn round_trip() {
        let mut b = Vec::new();
        encode(&fields(7), &mut b);
        assert_eq!(b.len(), FRAME_LEN);
        let f = Frame::check(&b).unwrap();
        assert_eq!(f.counter(), 7);
        assert_eq!(f.time_ns(), 7_000_000);
        assert_eq!(f.accel(), [0.1, -0.2, 9.81]);
        assert_eq!(f.gyro(), [0.01, 100.0, -3.5]);
        assert_eq!(f.temp_c(), Some(25.5));
        assert_eq!(f.flags(), FLAG_GYRO_SATURATED);
    }

    #[test]
    fn any_flipped_bit_is_refused() {
        let mut b = Vec::new();
        encode(&fields(3), &mut b);
        for i in 0..b.len() {
            let mut c = b.clone();
            c[i] ^= 0x10;
            assert!(Frame::check(&c).is_none(), "byte {i}");
        }
    }
}
