//! The layer's own state and the serialized FMU state format (FMI 2.0 section 2.1.8,
//! `fmi2SerializeFMUstate`, `fmi2DeSerializeFMUstate`).
//!
//! Format version 2, little-endian, no pointers, no padding (the pieces: [`crate::codec`]):
//!
//! | bytes | content |
//! |---|---|
//! | 8 | magic `b"RSFMI2ST"` |
//! | 4 | format version (u32) = 2 |
//! | 8 + n | model identifier (u64 length, UTF-8 bytes) |
//! | 8 + n | GUID (u64 length, UTF-8 bytes) |
//! | 1 | call state code (1 instantiated .. 5 terminated) |
//! | 8 | start time (f64) |
//! | 1 + 8 | stop time defined (0/1), stop time (f64) |
//! | 1 + 8 | tolerance defined (0/1), tolerance (f64) |
//! | 8 | time since start in nanoseconds (i64) |
//! | 8 | number of completed steps (u64) |
//! | 8 + n | model state (u64 length, bytes of `Fmi2Model::serialize_state`) |
//! | 4 | CRC-32 of every byte before it (u32) |
//!
//! The checksum is CRC-32 (ISO-HDLC, the polynomial of IEEE 802.3 and zlib) computed with
//! the `crc32fast` crate (<https://docs.rs/crc32fast>): it detects every error of one to
//! three bits and every burst of up to 32 bits in a message of this size (Koopman, "32-bit
//! cyclic redundancy codes for Internet applications", DSN 2002), so no single flipped bit
//! goes unnoticed. It guards against corruption, not against a forger.
//!
//! Reading checks, in this order, each with its own message: the magic, the format version,
//! the checksum, the model identifier and GUID, the length of every part, then that the
//! state makes sense: a call state an FMU can continue from (never `error` or `fatal`),
//! finite start and stop times and tolerance, a time counter `>= 0` whose time is finite and
//! not past the stop time. The model then checks its own part
//! ([`Fmi2Model::deserialize_state`](crate::Fmi2Model::deserialize_state)) and the layer
//! that the model's time matches the clock ([`Fmi2Model::time`](crate::Fmi2Model::time)).
//! The last successful time is not stored: it always equals the internal time, which a
//! discarded step does not advance.

use crate::codec::{put_f64, put_str, put_u64, Reader};
use crate::state::CallState;

/// First bytes of every serialized FMU state of this layer.
pub(crate) const MAGIC: [u8; 8] = *b"RSFMI2ST";
/// Current format version.
pub(crate) const FORMAT_VERSION: u32 = 2;
/// Bytes of the trailing checksum.
const CRC_BYTES: usize = 4;

/// What the layer keeps per instance besides the model; part of every FMU state.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct LayerState {
    pub(crate) call_state: CallState,
    pub(crate) start_time: f64,
    pub(crate) stop_time: Option<f64>,
    pub(crate) tolerance: Option<f64>,
    /// Nanoseconds since `start_time`; advanced by `round(h * 1e9)` per accepted step.
    pub(crate) time_ns: i64,
    /// Accepted steps since the start.
    pub(crate) steps: u64,
}

impl LayerState {
    pub(crate) fn new() -> Self {
        LayerState {
            call_state: CallState::Instantiated,
            start_time: 0.0,
            stop_time: None,
            tolerance: None,
            time_ns: 0,
            steps: 0,
        }
    }

    /// Internal time `start + ns / 1e9` (division, not `* 1e-9`, so that whole-nanosecond
    /// times such as 0.1 s come out as the nearest double).
    pub(crate) fn time(&self) -> f64 {
        self.start_time + ns_to_s(self.time_ns)
    }

    /// Whether an instance can go on from this state: an FMU state taken after `fmi2Error`
    /// or `fmi2Fatal` cannot (FMI 2.0 section 2.1.3: the instance is unusable then), so it
    /// is neither serialized nor restored from bytes.
    pub(crate) fn check_continuable(&self) -> Result<(), String> {
        match self.call_state {
            CallState::Error | CallState::Fatal => Err(format!(
                "the state records the call state {}: an instance cannot continue from it",
                self.call_state.name()
            )),
            _ => Ok(()),
        }
    }

    /// The checks of a state read from bytes (module docs) besides the call state.
    fn check_times(&self) -> Result<(), String> {
        let bad = |what: String| Err(format!("implausible state: {what}"));
        if !self.start_time.is_finite() {
            return bad(format!("start time {} is not finite", self.start_time));
        }
        if let Some(stop) = self
            .stop_time
            .filter(|s| !(s.is_finite() && *s >= self.start_time))
        {
            return bad(format!(
                "stop time {stop} is not a finite time >= the start time {}",
                self.start_time
            ));
        }
        if let Some(tol) = self.tolerance.filter(|t| !(t.is_finite() && *t > 0.0)) {
            return bad(format!("tolerance {tol} is not finite and > 0"));
        }
        let t = self.time();
        if self.time_ns < 0 || !t.is_finite() {
            return bad(format!(
                "time counter {} ns (time {t} s) is negative or not finite",
                self.time_ns
            ));
        }
        if let Some(stop) = self.stop_time {
            let tol = 1e-5 * stop.abs().max(1.0);
            if t > stop + tol {
                return bad(format!(
                    "time {t} s (counter {} ns) is past the stop time {stop} s",
                    self.time_ns
                ));
            }
        }
        Ok(())
    }
}

/// Nanoseconds to seconds.
pub(crate) fn ns_to_s(ns: i64) -> f64 {
    ns as f64 / 1e9
}

fn put_opt_f64(out: &mut Vec<u8>, v: Option<f64>) {
    out.push(u8::from(v.is_some()));
    put_f64(out, v.unwrap_or(0.0));
}

/// Appends the serialized state to `out`; `model` appends the model's own bytes.
pub(crate) fn encode(
    out: &mut Vec<u8>,
    model_identifier: &str,
    guid: &str,
    layer: &LayerState,
    model: impl FnOnce(&mut Vec<u8>),
) {
    let begin = out.len();
    out.extend_from_slice(&MAGIC);
    out.extend_from_slice(&FORMAT_VERSION.to_le_bytes());
    put_str(out, model_identifier);
    put_str(out, guid);
    out.push(layer.call_state.code());
    put_f64(out, layer.start_time);
    put_opt_f64(out, layer.stop_time);
    put_opt_f64(out, layer.tolerance);
    out.extend_from_slice(&layer.time_ns.to_le_bytes());
    put_u64(out, layer.steps);
    let len_at = out.len();
    put_u64(out, 0);
    let model_start = out.len();
    model(out);
    let model_len = (out.len() - model_start) as u64;
    out[len_at..model_start].copy_from_slice(&model_len.to_le_bytes());
    seal(out, begin);
}

/// Appends the CRC-32 of `out[begin..]`.
fn seal(out: &mut Vec<u8>, begin: usize) {
    let crc = crc32fast::hash(&out[begin..]);
    out.extend_from_slice(&crc.to_le_bytes());
}

/// Checks magic, version and checksum; returns the bytes the checksum covers.
fn unseal(bytes: &[u8]) -> Result<&[u8], String> {
    let mut r = Reader::new(bytes, "the serialized FMU state");
    if r.array::<8>("the magic")? != MAGIC {
        return Err(
            "wrong magic: these bytes are not an FMU state serialized by this layer".into(),
        );
    }
    let version = r.u32("the format version")?;
    if version != FORMAT_VERSION {
        return Err(format!(
            "unsupported format version {version} (this FMU reads version {FORMAT_VERSION})"
        ));
    }
    let body_len = bytes.len().saturating_sub(CRC_BYTES).max(r.position());
    let (body, stored) = bytes.split_at(body_len);
    let mut crc = Reader::new(stored, "the serialized FMU state");
    let stored = crc.u32("the checksum")?;
    let computed = crc32fast::hash(body);
    if stored != computed {
        return Err(format!(
            "checksum mismatch: the state is corrupt (CRC-32 stored {stored:#010x}, computed {computed:#010x} over {} bytes)",
            body.len()
        ));
    }
    Ok(body)
}

/// Parses a serialized state, checking it (module docs) except the model's part.
/// Returns the layer state and the model's bytes.
pub(crate) fn decode<'a>(
    bytes: &'a [u8],
    model_identifier: &str,
    guid: &str,
) -> Result<(LayerState, &'a [u8]), String> {
    let (layer, model) = parse(bytes, model_identifier, guid)?;
    layer.check_continuable()?;
    layer.check_times()?;
    Ok((layer, model))
}

/// [`decode`] without the checks of the layer state's sense.
pub(crate) fn parse<'a>(
    bytes: &'a [u8],
    model_identifier: &str,
    guid: &str,
) -> Result<(LayerState, &'a [u8]), String> {
    let body = unseal(bytes)?;
    let mut r = Reader::new(body, "the serialized FMU state");
    r.take(12, "the header")?;
    let id = r.bytes("the model identifier")?;
    if id != model_identifier.as_bytes() {
        return Err(format!(
            "model identifier mismatch: the state belongs to '{}', this FMU is '{model_identifier}'",
            String::from_utf8_lossy(id)
        ));
    }
    let g = r.bytes("the GUID")?;
    if g != guid.as_bytes() {
        return Err(format!(
            "GUID mismatch: the state has {}, this FMU has {guid}",
            String::from_utf8_lossy(g)
        ));
    }
    let code = r.array::<1>("the call state")?[0];
    let call_state = CallState::from_code(code)
        .ok_or_else(|| format!("corrupt state: unknown call state code {code}"))?;
    let start_time = r.f64("the start time")?;
    let stop_time = opt_f64(&mut r, "the stop time")?;
    let tolerance = opt_f64(&mut r, "the tolerance")?;
    let time_ns = i64::from_le_bytes(r.array("the time counter")?);
    let steps = r.u64("the step counter")?;
    let model = r.bytes("the model state")?;
    r.finish()?;
    let layer = LayerState {
        call_state,
        start_time,
        stop_time,
        tolerance,
        time_ns,
        steps,
    };
    Ok((layer, model))
}

fn opt_f64(r: &mut Reader<'_>, what: &str) -> Result<Option<f64>, String> {
    let defined = r.flag(what)?;
    let v = r.f64(what)?;
    Ok(defined.then_some(v))
}

/// Largest difference (s) between the layer's clock and a model's own time in a
/// deserialized state: 1 us, far above the rounding of either, far below a step.
pub(crate) const TIME_TOLERANCE: f64 = 1e-6;

/// Checks the model's time `model_time` against the layer's clock of the same state.
pub(crate) fn check_model_time(layer: &LayerState, model_time: Option<f64>) -> Result<(), String> {
    let Some(tm) = model_time else {
        return Ok(());
    };
    let t = layer.time();
    if (tm - t).abs() <= TIME_TOLERANCE {
        Ok(())
    } else {
        Err(format!(
            "implausible state: the model's time {tm} s does not match the clock's {t} s (counter {} ns)",
            layer.time_ns
        ))
    }
}

#[cfg(test)]
#[allow(clippy::unwrap_used)]
mod tests {
    use super::*;

    fn sample() -> LayerState {
        LayerState {
            call_state: CallState::StepComplete,
            start_time: 1.5,
            stop_time: Some(10.0),
            tolerance: None,
            time_ns: 123_456_789,
            steps: 42,
        }
    }

    fn bytes() -> Vec<u8> {
        let mut out = Vec::new();
        encode(&mut out, "Lag", "{g}", &sample(), |o| {
            o.extend_from_slice(b"model")
        });
        out
    }

    fn decode_err(b: &[u8]) -> String {
        match decode(b, "Lag", "{g}") {
            Err(e) => e,
            Ok(_) => panic!("should fail"),
        }
    }

    #[test]
    fn round_trip() {
        let b = bytes();
        assert_eq!(&b[..8], b"RSFMI2ST");
        let (layer, model) = decode(&b, "Lag", "{g}").unwrap_or_else(|e| panic!("{e}"));
        assert_eq!(layer, sample());
        assert_eq!(model, b"model");
        assert_eq!(layer.time(), 1.5 + 0.123456789);
    }

    /// `b` with the layer state replaced by `f(layer)` and the checksum made anew: what
    /// a forger (or a bug) would write.
    fn resealed(f: impl FnOnce(&mut LayerState)) -> Vec<u8> {
        let mut layer = sample();
        f(&mut layer);
        let mut out = Vec::new();
        encode(&mut out, "Lag", "{g}", &layer, |o| {
            o.extend_from_slice(b"model")
        });
        out
    }

    #[test]
    fn every_corruption_is_named() {
        let b = bytes();
        let mut m = b.clone();
        m[0] = b'X';
        assert!(decode_err(&m).contains("wrong magic"));
        let mut v = b.clone();
        v[8] = 9;
        assert!(decode_err(&v).contains("format version 9"));
        assert!(matches!(decode(&b, "Other", "{g}"), Err(e) if e.contains("model identifier")));
        assert!(matches!(decode(&b, "Lag", "{h}"), Err(e) if e.contains("GUID mismatch")));
        assert!(decode_err(&b[..b.len() - 1]).contains("checksum mismatch"));
        let mut t = b.clone();
        t.push(0);
        assert!(decode_err(&t).contains("checksum mismatch"));
        assert!(decode_err(&[]).contains("truncated"));
        assert!(decode_err(&b[..14]).contains("truncated"));
    }

    #[test]
    fn every_single_bit_flip_is_refused() {
        let b = bytes();
        for bit in 0..8 * b.len() {
            let mut m = b.clone();
            m[bit / 8] ^= 1 << (bit % 8);
            assert!(decode(&m, "Lag", "{g}").is_err(), "bit {bit} accepted");
        }
    }

    #[test]
    fn a_resealed_state_is_still_checked_for_sense() {
        for (state, name) in [(CallState::Fatal, "fatal"), (CallState::Error, "error")] {
            let e = decode_err(&resealed(|l| l.call_state = state));
            assert_eq!(
                e,
                format!(
                    "the state records the call state {name}: an instance cannot continue from it"
                )
            );
        }
        let e = decode_err(&resealed(|l| l.time_ns = i64::MAX));
        assert!(e.contains("past the stop time 10 s"), "{e}");
        let e = decode_err(&resealed(|l| l.time_ns = -1));
        assert!(e.contains("negative"), "{e}");
        let e = decode_err(&resealed(|l| l.start_time = f64::NAN));
        assert!(e.contains("start time NaN is not finite"), "{e}");
        let e = decode_err(&resealed(|l| l.stop_time = Some(f64::INFINITY)));
        assert!(e.contains("stop time inf"), "{e}");
        let e = decode_err(&resealed(|l| l.tolerance = Some(-1.0)));
        assert!(e.contains("tolerance -1"), "{e}");
        let layer = sample();
        assert!(check_model_time(&layer, Some(layer.time())).is_ok());
        assert!(check_model_time(&layer, None).is_ok());
        let e = check_model_time(&layer, Some(layer.time() + 1.0)).unwrap_err();
        assert!(
            e.contains("does not match the clock's 1.623456789 s"),
            "{e}"
        );
    }
}
