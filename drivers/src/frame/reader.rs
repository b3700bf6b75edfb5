//! Finds frames in a byte stream: resynchronises on the sync bytes after garbage, and
//! counts frames whose CRC fails instead of stopping on them.

use super::{FRAME_LEN, Frame, PAYLOAD_LEN, SYNC};

/// A receive buffer and the frames found in it.
#[derive(Debug, Default)]
pub struct FrameReader {
    buf: Vec<u8>,
    start: usize,
    /// Frames refused for a wrong CRC.
    pub corrupted: u64,
    /// Bytes skipped while looking for a sync (a partial frame at the start of a link).
    pub skipped_bytes: u64,
}

impl FrameReader {
    /// An empty reader.
    pub fn new() -> Self {
        FrameReader::default()
    }

    /// The buffer to append received bytes to (`AsyncReadExt::read_buf`); consumed bytes
    /// are dropped from its front first.
    pub fn buffer(&mut self) -> &mut Vec<u8> {
        if self.start > 0 {
            self.buf.drain(..self.start);
            self.start = 0;
        }
        self.buf.reserve(4096);
        &mut self.buf
    }

    /// Forgets buffered bytes (after a reconnect).
    pub fn clear(&mut self) {
        self.buf.clear();
        self.start = 0;
    }

    /// Calls `f` on every complete, checked frame in the buffer, in order.
    pub fn frames(&mut self, mut f: impl FnMut(Frame<'_>)) {
        loop {
            let data = &self.buf[self.start..];
            let Some(p) = data.windows(2).position(|w| w == SYNC) else {
                // Keep a last byte that may be the first half of a sync.
                let keep = usize::from(data.last() == Some(&SYNC[0]));
                self.skipped_bytes += (data.len() - keep) as u64;
                self.start += data.len() - keep;
                return;
            };
            self.skipped_bytes += p as u64;
            self.start += p;
            let data = &self.buf[self.start..];
            if data.len() < FRAME_LEN {
                return;
            }
            match Frame::check(&data[..FRAME_LEN]) {
                Some(frame) => {
                    f(frame);
                    self.start += FRAME_LEN;
                }
                None => {
                    if data[2] as usize == PAYLOAD_LEN {
                        self.corrupted += 1;
                    } else {
                        self.skipped_bytes += 1;
                    }
                    self.start += 1;
                }
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::super::{FrameFields, encode};
    use super::*;

    fn frame(counter: u32) -> Vec<u8> {
        let mut b = Vec::new();
        encode(
            &FrameFields {
                counter,
                time_ns: u64::from(counter) * 500_000,
                accel: [0.0, 0.0, 9.8],
                gyro: [0.0; 3],
                temp_c: f64::NAN,
                flags: 0,
            },
            &mut b,
        );
        b
    }

    #[test]
    fn garbage_split_frames_and_a_corrupted_one() {
        let mut stream = vec![1, 2, 0xA5, 3];
        for k in 0..5 {
            let mut f = frame(k);
            if k == 2 {
                f[20] ^= 0xFF;
            }
            stream.extend(f);
        }
        let mut r = FrameReader::new();
        let mut seen = Vec::new();
        // Fed in awkward pieces: every frame boundary falls inside a read.
        for piece in stream.chunks(13) {
            r.buffer().extend_from_slice(piece);
            r.frames(|f| seen.push(f.counter()));
        }
        assert_eq!(seen, vec![0, 1, 3, 4]);
        assert_eq!(r.corrupted, 1);
        assert_eq!(r.skipped_bytes, 4 + FRAME_LEN as u64 - 1);
    }
}
