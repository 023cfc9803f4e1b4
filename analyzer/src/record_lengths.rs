//! The length fields inside an MCAP record, checked against the record's own size before
//! the mcap crate parses it.
//!
//! mcap 0.26's record parser sizes a buffer by a string's or a byte array's length prefix
//! before it reads the bytes: a corrupted prefix (one flipped bit in a Metadata record's
//! string) made it allocate 4 GB, and abort where memory is limited (found by
//! `fuzz-mcap`). The records the analyzer parses (docs/logging.md, MCAP specification):
//!
//! | record | layout |
//! |---|---|
//! | Schema (0x03) | id u16, name string, encoding string, data: u32 length + bytes |
//! | Channel (0x04) | id u16, schema id u16, topic string, message encoding string, metadata map |
//! | Message (0x05) | channel id u16, sequence u32, log time u64, publish time u64, data (the rest) |
//! | Attachment (0x09) | log time u64, create time u64, name string, media type string, data: u64 length + bytes, crc u32 |
//! | Metadata (0x0C) | name string, metadata map |
//!
//! A string is a u32 length and that many bytes; a map is a u32 length in bytes and that
//! many bytes of (string, string) pairs. Every other record is not parsed at all.

use mcap::records::op;

/// Whether the analyzer parses records of `opcode` (the others are skipped unread).
#[must_use]
pub fn parsed(opcode: u8) -> bool {
    matches!(
        opcode,
        op::SCHEMA | op::CHANNEL | op::MESSAGE | op::ATTACHMENT | op::METADATA
    )
}

/// Checks that every length field of the record `data` (of `opcode`) fits in the record.
///
/// # Errors
/// The field whose length runs past the record's end, with both sizes.
pub fn check(opcode: u8, data: &[u8]) -> Result<(), String> {
    let mut c = Fields { data, at: 0 };
    match opcode {
        op::SCHEMA => {
            c.fixed(2, "id")?;
            c.string("name")?;
            c.string("encoding")?;
            c.bytes(4, "data")
        }
        op::CHANNEL => {
            c.fixed(4, "ids")?;
            c.string("topic")?;
            c.string("message encoding")?;
            c.map("metadata")
        }
        op::MESSAGE => c.fixed(22, "header"),
        op::ATTACHMENT => {
            c.fixed(16, "times")?;
            c.string("name")?;
            c.string("media type")?;
            c.bytes(8, "data")?;
            c.fixed(4, "crc")
        }
        op::METADATA => {
            c.string("name")?;
            c.map("metadata")
        }
        _ => Ok(()),
    }
}

/// A cursor over a record's fields.
struct Fields<'a> {
    data: &'a [u8],
    at: usize,
}

impl Fields<'_> {
    fn left(&self) -> usize {
        self.data.len() - self.at
    }

    /// Skips `n` bytes of field `what`.
    fn fixed(&mut self, n: usize, what: &str) -> Result<(), String> {
        if n > self.left() {
            return Err(format!(
                "its {what} needs {n} bytes, the record has {} left",
                self.left()
            ));
        }
        self.at += n;
        Ok(())
    }

    /// A little-endian length of `width` bytes (4 or 8).
    fn length(&mut self, width: usize, what: &str) -> Result<u64, String> {
        let start = self.at;
        self.fixed(width, what)?;
        let mut bytes = [0u8; 8];
        bytes[..width].copy_from_slice(&self.data[start..start + width]);
        Ok(u64::from_le_bytes(bytes))
    }

    /// A length of `width` bytes and that many bytes.
    fn bytes(&mut self, width: usize, what: &str) -> Result<(), String> {
        let len = self.length(width, what)?;
        match usize::try_from(len) {
            Ok(n) if n <= self.left() => {
                self.at += n;
                Ok(())
            }
            _ => Err(format!(
                "its {what} claims {len} bytes, the record has {} left",
                self.left()
            )),
        }
    }

    fn string(&mut self, what: &str) -> Result<(), String> {
        self.bytes(4, what)
    }

    /// A map: a u32 length in bytes, then (string, string) pairs filling it exactly.
    fn map(&mut self, what: &str) -> Result<(), String> {
        let len = self.length(4, what)?;
        let end = match usize::try_from(len) {
            Ok(n) if n <= self.left() => self.at + n,
            _ => {
                return Err(format!(
                    "its {what} claims {len} bytes, the record has {} left",
                    self.left()
                ))
            }
        };
        let mut inner = Fields {
            data: &self.data[..end],
            at: self.at,
        };
        while inner.at < end {
            inner.string(what)?;
            inner.string(what)?;
        }
        self.at = end;
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn string(s: &str) -> Vec<u8> {
        let mut v = u32::try_from(s.len()).unwrap_or(0).to_le_bytes().to_vec();
        v.extend_from_slice(s.as_bytes());
        v
    }

    #[test]
    fn a_length_beyond_the_record_is_refused_before_parsing() {
        // Metadata `run` with one pair.
        let mut pairs = string("unit");
        pairs.extend(string("TowingPlant"));
        let mut good = string("run");
        good.extend(u32::try_from(pairs.len()).unwrap_or(0).to_le_bytes());
        good.extend(&pairs);
        check(op::METADATA, &good).expect("a sound record");
        assert!(mcap::parse_record(op::METADATA, &good).is_ok());
        // The flipped bit fuzz-mcap found: a string length of about 4e9.
        let mut bad = good.clone();
        bad[3] ^= 0x80;
        let e = check(op::METADATA, &bad).expect_err("too long");
        assert!(e.contains("its name claims 2147483651 bytes"), "{e}");
        // A map entry that runs past the map.
        let mut bad = good.clone();
        let key_len = 4 + 3 + 4;
        bad[key_len] = 200;
        assert!(check(op::METADATA, &bad).is_err());
        // Cut short anywhere: refused, never a panic.
        for n in 0..good.len() {
            assert!(check(op::METADATA, &good[..n]).is_err(), "cut at {n}");
        }
        // Records the analyzer does not parse are not checked.
        assert!(check(op::MESSAGE_INDEX, &[0xff; 3]).is_ok());
        assert!(!parsed(op::MESSAGE_INDEX) && parsed(op::METADATA));
    }
}
