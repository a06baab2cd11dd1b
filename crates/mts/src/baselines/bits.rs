//! Bit-level writer and reader for the baselines' compact formats (the
//! progressive mesh file and the cluster-tree packet stream).
//!
//! Bits are packed least significant first into bytes. The reader never
//! reads past its input: every read is checked and a short input is an
//! [`Error::Parse`] naming the byte offset and the element being read.

use crate::error::{Error, Place, Result};
use std::path::PathBuf;

/// Bits needed to write any value below `count` (0 for `count <= 1`).
#[must_use]
pub(crate) fn width_for(count: u64) -> u32 {
    if count <= 1 {
        0
    } else {
        64 - (count - 1).leading_zeros()
    }
}

/// Appends bit fields to a byte vector.
#[derive(Debug, Default)]
pub(crate) struct BitWriter {
    bytes: Vec<u8>,
    /// Bits used in the last byte (0 when it is full or absent).
    used: u32,
}

impl BitWriter {
    /// Writes the low `width` bits of `value` (`width <= 64`).
    pub(crate) fn put(&mut self, mut value: u64, mut width: u32) {
        debug_assert!(
            width == 64 || value >> width == 0,
            "{value} needs more than {width} bits"
        );
        while width > 0 {
            if self.used == 0 {
                self.bytes.push(0);
            }
            let room = 8 - self.used;
            let n = room.min(width);
            let last = self.bytes.len() - 1;
            self.bytes[last] |= ((value & ((1u64 << n) - 1)) as u8) << self.used;
            value = if n == 64 { 0 } else { value >> n };
            width -= n;
            self.used = (self.used + n) % 8;
        }
    }

    /// Writes one bit.
    pub(crate) fn bit(&mut self, b: bool) {
        self.put(u64::from(b), 1);
    }

    /// Writes an `f32` as its 32 bits.
    pub(crate) fn f32(&mut self, x: f32) {
        self.put(u64::from(x.to_bits()), 32);
    }

    /// Elias-gamma code of `value + 1` (small counts cost few bits: 0 is one
    /// bit, 1 and 2 three bits).
    pub(crate) fn gamma(&mut self, value: u64) {
        let v = value + 1;
        let n = 63 - v.leading_zeros();
        self.put(0, n);
        // The top bit is the terminator, then the remaining n bits.
        self.bit(true);
        self.put(v & ((1u64 << n) - 1), n);
    }

    /// The bytes, the last one zero-padded.
    pub(crate) fn finish(self) -> Vec<u8> {
        self.bytes
    }
}

/// Reads bit fields written by [`BitWriter`], bounds-checked.
#[derive(Debug)]
pub(crate) struct BitReader<'a> {
    bytes: &'a [u8],
    /// Next bit to read.
    pos: u64,
    file: PathBuf,
    /// Whether a read failed for lack of bits (a prefix decoder stops
    /// quietly there; any other error is corruption).
    pub(crate) ran_out: bool,
}

impl<'a> BitReader<'a> {
    /// A reader over `bytes`; `file` names the input in errors.
    pub(crate) fn new(bytes: &'a [u8], file: &str) -> BitReader<'a> {
        BitReader {
            bytes,
            pos: 0,
            file: PathBuf::from(file),
            ran_out: false,
        }
    }

    /// Bits not read yet.
    pub(crate) fn remaining(&self) -> u64 {
        8 * self.bytes.len() as u64 - self.pos
    }

    /// Position of the next bit.
    pub(crate) fn position(&self) -> u64 {
        self.pos
    }

    /// An error at the current byte, reading `element`.
    pub(crate) fn error(&self, element: &str, message: impl Into<String>) -> Error {
        Error::Parse {
            file: self.file.clone(),
            place: Place {
                element: Some(element.to_owned()),
                ..Place::default()
            }
            .at_byte(self.pos / 8),
            message: message.into(),
        }
    }

    /// Reads `width` bits (`width <= 64`).
    ///
    /// # Errors
    /// [`Error::Parse`] ("truncated") when fewer bits remain.
    pub(crate) fn get(&mut self, width: u32, element: &str) -> Result<u64> {
        if self.remaining() < u64::from(width) {
            self.ran_out = true;
            return Err(self.error(
                element,
                format!("truncated: {width} bits needed, {} left", self.remaining()),
            ));
        }
        let mut value = 0u64;
        let mut done = 0u32;
        while done < width {
            let byte = self.bytes[(self.pos / 8) as usize];
            let at = (self.pos % 8) as u32;
            let n = (8 - at).min(width - done);
            let bits = (u64::from(byte) >> at) & ((1u64 << n) - 1);
            value |= bits << done;
            done += n;
            self.pos += u64::from(n);
        }
        Ok(value)
    }

    /// Reads one bit.
    ///
    /// # Errors
    /// As [`BitReader::get`].
    pub(crate) fn bit(&mut self, element: &str) -> Result<bool> {
        Ok(self.get(1, element)? == 1)
    }

    /// Reads an `f32` and checks that it is finite.
    ///
    /// # Errors
    /// Truncation, or a non-finite value.
    pub(crate) fn finite_f32(&mut self, element: &str) -> Result<f32> {
        let x = f32::from_bits(self.get(32, element)? as u32);
        if x.is_finite() {
            Ok(x)
        } else {
            Err(self.error(element, format!("non-finite coordinate {x}")))
        }
    }

    /// Reads a value below `bound`, written with `width_for(bound)` bits.
    ///
    /// # Errors
    /// Truncation, or a value at or above `bound`.
    pub(crate) fn below(&mut self, bound: u64, element: &str) -> Result<u64> {
        let v = self.get(width_for(bound), element)?;
        if v >= bound {
            return Err(self.error(element, format!("{v} is not below {bound}")));
        }
        Ok(v)
    }

    /// Reads an Elias-gamma value written by [`BitWriter::gamma`].
    ///
    /// # Errors
    /// Truncation, or a code longer than 63 bits.
    pub(crate) fn gamma(&mut self, element: &str) -> Result<u64> {
        let mut n = 0u32;
        while !self.bit(element)? {
            n += 1;
            if n > 62 {
                return Err(self.error(element, "gamma code longer than 63 bits"));
            }
        }
        let rest = self.get(n, element)?;
        Ok(((1u64 << n) | rest) - 1)
    }

    /// Fails unless only zero padding of the last byte remains.
    ///
    /// # Errors
    /// [`Error::Parse`] naming the trailing bytes.
    pub(crate) fn finish(&mut self, element: &str) -> Result<()> {
        if self.remaining() >= 8 {
            return Err(self.error(
                element,
                format!("{} unexpected bytes at the end", self.remaining() / 8),
            ));
        }
        let n = self.remaining() as u32;
        if self.get(n, element)? != 0 {
            return Err(self.error(element, "non-zero padding bits at the end"));
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn fields_round_trip() {
        let mut w = BitWriter::default();
        w.put(5, 3);
        w.gamma(0);
        w.gamma(41);
        w.f32(-1.5);
        w.put(u64::MAX, 64);
        w.bit(true);
        let bytes = w.finish();
        let mut r = BitReader::new(&bytes, "<memory>");
        assert_eq!(r.get(3, "a").unwrap(), 5);
        assert_eq!(r.gamma("b").unwrap(), 0);
        assert_eq!(r.gamma("c").unwrap(), 41);
        assert_eq!(r.finite_f32("d").unwrap(), -1.5);
        assert_eq!(r.get(64, "e").unwrap(), u64::MAX);
        assert!(r.bit("f").unwrap());
        r.finish("end").unwrap();
        assert!(r.get(1, "g").is_err());
    }

    #[test]
    fn widths() {
        assert_eq!(width_for(0), 0);
        assert_eq!(width_for(1), 0);
        assert_eq!(width_for(2), 1);
        assert_eq!(width_for(256), 8);
        assert_eq!(width_for(257), 9);
    }
}
