//! Mutations of a seed input: one to four of [`Op`] in a row, each at a random place.

use crate::rng::Rng;

/// Values a numeric token is replaced by: the ends of f64, i64, u64, i32, u32 and just
/// beyond, subnormals, zeros, the special floats TOML accepts, absurd precision.
pub const EXTREMES: [&str; 30] = [
    "1.7976931348623157e308",
    "-1.7976931348623157e308",
    "1e309",
    "-1e309",
    "4.9e-324",
    "2.2250738585072014e-308",
    "-0.0",
    "0",
    "0.0",
    "1e-320",
    "nan",
    "-nan",
    "inf",
    "-inf",
    "+inf",
    "9223372036854775807",
    "-9223372036854775808",
    "9223372036854775808",
    "18446744073709551615",
    "18446744073709551616",
    "4294967295",
    "4294967296",
    "2147483647",
    "-2147483649",
    "1e22",
    "123456789012345678901234567890.5",
    "0.1e400",
    "1_000",
    "-1",
    "3600000000",
];

/// Integers written over 1, 2, 4 or 8 bytes of a binary field (lengths, counts, ids).
const INTEGERS: [u64; 10] = [
    0,
    1,
    0x7f,
    0x80,
    0xff,
    0x7fff_ffff,
    0xffff_ffff,
    0x8000_0000_0000_0000,
    u64::MAX,
    1 << 40,
];

/// One kind of mutation.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Op {
    /// Flip one bit.
    FlipBit,
    /// Set one byte to a random or a boundary value.
    SetByte,
    /// Insert 1 to 16 random bytes, or a copy of a stretch of the input.
    Insert,
    /// Delete a stretch of up to 64 bytes.
    Delete,
    /// Copy a stretch of another seed (or this one) in, inserted or written over.
    Splice,
    /// Replace a numeric token (digits, sign, point, exponent) by one of [`EXTREMES`].
    Number,
    /// Write one of [`INTEGERS`] over 1, 2, 4 or 8 bytes (little endian).
    Integer,
    /// Cut the input at a random length.
    Truncate,
}

/// The operations in the order [`mutate`] draws them (numbers twice as often).
const OPS: [Op; 9] = [
    Op::FlipBit,
    Op::SetByte,
    Op::Insert,
    Op::Delete,
    Op::Splice,
    Op::Number,
    Op::Number,
    Op::Integer,
    Op::Truncate,
];

/// `base` with one to four mutations; `corpus` gives the splices their material.
#[must_use]
pub fn mutate(rng: &mut Rng, base: &[u8], corpus: &[Vec<u8>]) -> Vec<u8> {
    let mut out = base.to_vec();
    for _ in 0..1 + rng.below(4) {
        let op = OPS[rng.below(OPS.len())];
        apply(rng, op, &mut out, corpus);
    }
    out
}

/// Applies `op` to `out` at a random place.
pub fn apply(rng: &mut Rng, op: Op, out: &mut Vec<u8>, corpus: &[Vec<u8>]) {
    let n = out.len();
    match op {
        Op::FlipBit if n > 0 => {
            let bit = rng.below(n * 8);
            out[bit / 8] ^= 1 << (bit % 8);
        }
        Op::SetByte if n > 0 => {
            let at = rng.below(n);
            out[at] = [0, 0xff, 0x7f, 0x80, rng.next_u64().to_le_bytes()[0]][rng.below(5)];
        }
        Op::Insert => {
            let at = rng.below(n + 1);
            let bytes: Vec<u8> = if n > 0 && rng.one_in(2) {
                let from = rng.below(n);
                let len = 1 + rng.below((n - from).min(256));
                out[from..from + len].to_vec()
            } else {
                (0..1 + rng.below(16))
                    .map(|_| rng.next_u64().to_le_bytes()[0])
                    .collect()
            };
            out.splice(at..at, bytes);
        }
        Op::Delete if n > 0 => {
            let at = rng.below(n);
            let len = 1 + rng.below((n - at).min(64));
            out.drain(at..at + len);
        }
        Op::Splice => splice(rng, out, corpus),
        Op::Number => number(rng, out),
        Op::Integer if n > 0 => {
            let width = [1, 2, 4, 8][rng.below(4)].min(n);
            let at = rng.below(n - width + 1);
            let value = INTEGERS[rng.below(INTEGERS.len())].to_le_bytes();
            out[at..at + width].copy_from_slice(&value[..width]);
        }
        Op::Truncate if n > 0 => out.truncate(rng.below(n)),
        _ => {}
    }
}

/// A stretch of a random seed, inserted at or written over a random place of `out`.
fn splice(rng: &mut Rng, out: &mut Vec<u8>, corpus: &[Vec<u8>]) {
    let Some(donor) = corpus.get(rng.below(corpus.len())) else {
        return;
    };
    if donor.is_empty() {
        return;
    }
    let from = rng.below(donor.len());
    let len = 1 + rng.below((donor.len() - from).min(4096));
    let piece = &donor[from..from + len];
    let at = rng.below(out.len() + 1);
    if rng.one_in(2) {
        out.splice(at..at, piece.iter().copied());
    } else {
        let end = (at + len).min(out.len());
        out.splice(at..end, piece.iter().copied());
    }
}

/// Replaces a random numeric token of `out` by one of [`EXTREMES`] (nothing when it has
/// none).
fn number(rng: &mut Rng, out: &mut Vec<u8>) {
    let tokens = numeric_tokens(out);
    if tokens.is_empty() {
        return;
    }
    let (start, end) = tokens[rng.below(tokens.len())];
    let value = EXTREMES[rng.below(EXTREMES.len())].as_bytes();
    out.splice(start..end, value.iter().copied());
}

/// The numeric tokens of `text` as byte ranges: a digit not preceded by a letter, digit,
/// `_` or `.`, with a sign before it, and the digits, points, exponents and signs after.
#[must_use]
pub fn numeric_tokens(text: &[u8]) -> Vec<(usize, usize)> {
    let word = |b: u8| b.is_ascii_alphanumeric() || b == b'_' || b == b'.';
    let mut tokens = Vec::new();
    let mut i = 0;
    while i < text.len() {
        if !text[i].is_ascii_digit() || (i > 0 && word(text[i - 1])) {
            i += 1;
            continue;
        }
        let start = if i > 0 && (text[i - 1] == b'-' || text[i - 1] == b'+') {
            i - 1
        } else {
            i
        };
        let mut end = i;
        while end < text.len()
            && (text[end].is_ascii_digit()
                || matches!(text[end], b'.' | b'e' | b'E' | b'_')
                || (matches!(text[end], b'+' | b'-') && matches!(text[end - 1], b'e' | b'E')))
        {
            end += 1;
        }
        tokens.push((start, end));
        i = end;
    }
    tokens
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn numeric_tokens_are_found_with_sign_and_exponent() {
        let text = b"x = -4.9\ny = 7.0e-3 # v2 and 12\nname = \"a1\"";
        let found: Vec<&[u8]> = numeric_tokens(text)
            .into_iter()
            .map(|(a, b)| &text[a..b])
            .collect();
        assert_eq!(found, vec![&b"-4.9"[..], b"7.0e-3", b"12"]);
    }

    #[test]
    fn every_op_keeps_within_bounds_and_a_run_is_deterministic() {
        let corpus = vec![b"a = 1.5\nb = [2, 3]\n".to_vec(), vec![0u8; 40], Vec::new()];
        for seed in 0..200u64 {
            let mut rng = Rng::new(seed);
            for op in OPS {
                for base in &corpus {
                    let mut out = base.clone();
                    apply(&mut rng, op, &mut out, &corpus);
                }
            }
        }
        let a = crate::input_for(3, 99, &corpus);
        assert_eq!(a, crate::input_for(3, 99, &corpus));
        let differ = (0..50)
            .filter(|&i| crate::input_for(3, i, &corpus) != a)
            .count();
        assert!(differ > 40, "{differ} of 50 differ");
        // Numbers are replaced by extremes.
        let mut rng = Rng::new(5);
        let mut out = corpus[0].clone();
        number(&mut rng, &mut out);
        let text = String::from_utf8_lossy(&out).into_owned();
        assert!(EXTREMES.iter().any(|e| text.contains(e)), "{text}");
    }
}
