//! The text a back end gathers before handing it to its output, written in place.
//!
//! Owns the batch buffer: bytes zeroed once and written at a cursor, so that a line of
//! numbers is written into room made for the longest such line, at once, with no copy
//! and no change of a vector's length per number ([`Gathered::room`]). It must not choose
//! what is written nor a number's form: the back end and [`crate::number`] do.

use crate::number::{
    copy_short, fits_fixed, push_exact, push_fixed, write_exact, write_fixed, EXACT_SLOT,
    FIXED_SLOT,
};
use std::io::{self, Write};

/// Bytes of room a growing [`Gathered`] zeroes ahead of its text.
const ZEROED_AHEAD: usize = 4096;

/// Text gathered for one output: `bytes[..used]`, the rest room to write into.
#[derive(Debug)]
pub(crate) struct Gathered {
    bytes: Vec<u8>,
    used: usize,
}

impl Gathered {
    /// A buffer with room for `capacity` bytes before it grows.
    pub(crate) fn with_capacity(capacity: usize) -> Gathered {
        Gathered {
            bytes: vec![0; capacity],
            used: 0,
        }
    }

    /// Bytes gathered.
    pub(crate) fn len(&self) -> usize {
        self.used
    }

    /// The text gathered.
    pub(crate) fn text(&self) -> &[u8] {
        &self.bytes[..self.used]
    }

    /// Forgets the text gathered (once written); the room stays.
    pub(crate) fn clear(&mut self) {
        self.used = 0;
    }

    /// At least `len` bytes of room after the text, to write into; [`Gathered::advance`]
    /// then keeps what was written. Only a buffer too small grows, by [`ZEROED_AHEAD`]
    /// bytes of zeros at a time (its capacity doubles as a vector's does, untouched), so a
    /// buffer that holds a whole array (MovePVT) is resident only as far as it is written.
    #[inline]
    pub(crate) fn room(&mut self, len: usize) -> &mut [u8] {
        let end = self.used + len;
        if end > self.bytes.len() {
            self.bytes
                .resize(end.max(self.bytes.len() + ZEROED_AHEAD), 0);
        }
        &mut self.bytes[self.used..end]
    }

    /// Keeps the next `len` bytes of room (written through [`Gathered::room`]) as text.
    #[inline]
    pub(crate) fn advance(&mut self, len: usize) {
        self.used += len;
    }

    /// Appends `text`.
    #[inline]
    pub(crate) fn push_slice(&mut self, text: &[u8]) {
        self.room(text.len()).copy_from_slice(text);
        self.advance(text.len());
    }

    /// Appends one byte.
    #[inline]
    pub(crate) fn push(&mut self, byte: u8) {
        self.room(1)[0] = byte;
        self.advance(1);
    }

    /// Appends `x` with `DECIMALS` decimals, as [`push_fixed`] writes it.
    #[inline]
    pub(crate) fn fixed<const DECIMALS: usize>(&mut self, x: f64) {
        if fits_fixed::<DECIMALS>(x) {
            let len = write_fixed::<DECIMALS>(self.room(FIXED_SLOT), x);
            self.advance(len);
        } else {
            let mut text = Vec::new();
            push_fixed::<DECIMALS>(&mut text, x);
            self.push_slice(&text);
        }
    }
}

impl Gathered {
    /// Appends the shortest text that reads back as exactly `x`, as
    /// [`crate::number::push_exact`] writes it.
    #[inline]
    pub(crate) fn exact(&mut self, x: f64) {
        let len = write_exact(self.room(EXACT_SLOT), x);
        self.advance(len);
    }

    /// Appends `text`.
    #[inline]
    pub(crate) fn push_str(&mut self, text: &str) {
        self.push_slice(text.as_bytes());
    }

    /// Drops the last byte gathered, if any.
    pub(crate) fn pop(&mut self) {
        self.used = self.used.saturating_sub(1);
    }
}

impl Gathered {
    /// Appends `text` (at most [`EXACT_SLOT`] bytes: a number's digits) without a call
    /// into `memcpy`.
    #[inline]
    pub(crate) fn push_short(&mut self, text: &[u8]) {
        let len = copy_short(self.room(EXACT_SLOT), text);
        self.advance(len);
    }
}

/// Text a back end appends to: its gathered batch, or a string it holds for later.
pub(crate) trait TextOut {
    /// Appends `text`.
    fn put(&mut self, text: &str);
    /// Appends the shortest text that reads back as exactly `x`
    /// ([`crate::number::push_exact`]).
    fn exact(&mut self, x: f64);
}

impl TextOut for String {
    fn put(&mut self, text: &str) {
        self.push_str(text);
    }
    fn exact(&mut self, x: f64) {
        push_exact(self, x);
    }
}

impl TextOut for Gathered {
    #[inline]
    fn put(&mut self, text: &str) {
        self.push_slice(text.as_bytes());
    }
    #[inline]
    fn exact(&mut self, x: f64) {
        Gathered::exact(self, x);
    }
}

impl Write for Gathered {
    fn write(&mut self, buf: &[u8]) -> io::Result<usize> {
        self.push_slice(buf);
        Ok(buf.len())
    }

    fn flush(&mut self) -> io::Result<()> {
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn text_is_kept_across_growth_and_clear() {
        let mut g = Gathered::with_capacity(4);
        g.push_slice(b"TA");
        g.fixed::<4>(8.0117);
        g.push(b' ');
        g.fixed::<9>(-123.456789012);
        g.fixed::<2>(1e300);
        write!(g, "|{}", 7).unwrap();
        let mut expected = b"TA8.0117 -123.456789012".to_vec();
        push_fixed::<2>(&mut expected, 1e300);
        expected.extend_from_slice(b"|7");
        assert_eq!(g.text(), &expected[..]);
        assert_eq!(g.len(), expected.len());
        g.clear();
        g.push_slice(b"x");
        assert_eq!(g.text(), b"x");
    }

    #[test]
    fn room_written_but_not_advanced_is_not_text() {
        let mut g = Gathered::with_capacity(0);
        g.room(10).fill(b'z');
        g.advance(3);
        g.room(5)[0] = b'y';
        g.advance(1);
        assert_eq!(g.text(), b"zzzy");
    }
}
