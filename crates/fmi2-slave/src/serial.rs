//! The layer's own state and the serialized FMU state format (FMI 2.0 section 2.1.8,
//! `fmi2SerializeFMUstate`).
//!
//! Format version 1, all integers and floats little-endian, no pointers, no padding:
//!
//! | bytes | content |
//! |---|---|
//! | 8 | magic `b"RSFMI2ST"` |
//! | 4 | format version (u32) = 1 |
//! | 4 + n | model identifier (u32 length, UTF-8 bytes) |
//! | 4 + n | GUID (u32 length, UTF-8 bytes) |
//! | 1 | call state code (1 instantiated .. 7 fatal) |
//! | 8 | start time (f64) |
//! | 1 + 8 | stop time defined (0/1), stop time (f64) |
//! | 1 + 8 | tolerance defined (0/1), tolerance (f64) |
//! | 8 | time since start in nanoseconds (i64) |
//! | 8 | number of completed steps (u64) |
//! | 8 + n | model state (u64 length, bytes of `Fmi2Model::serialize_state`) |
//!
//! The buffer must be consumed exactly. The last successful time is not stored: it always
//! equals the internal time, which a discarded step does not advance.

use crate::state::CallState;

/// First bytes of every serialized FMU state of this layer.
pub(crate) const MAGIC: [u8; 8] = *b"RSFMI2ST";
/// Current format version.
pub(crate) const FORMAT_VERSION: u32 = 1;

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
}

/// Nanoseconds to seconds.
pub(crate) fn ns_to_s(ns: i64) -> f64 {
    ns as f64 / 1e9
}

fn put_u32(out: &mut Vec<u8>, v: u32) {
    out.extend_from_slice(&v.to_le_bytes());
}

fn put_str(out: &mut Vec<u8>, s: &str) {
    // Identifiers and GUIDs are short; saturate rather than panic on absurd lengths
    // (the reader then reports a mismatch).
    put_u32(out, u32::try_from(s.len()).unwrap_or(u32::MAX));
    out.extend_from_slice(s.as_bytes());
}

fn put_opt_f64(out: &mut Vec<u8>, v: Option<f64>) {
    out.push(u8::from(v.is_some()));
    out.extend_from_slice(&v.unwrap_or(0.0).to_le_bytes());
}

/// Appends the serialized state to `out`; `model` appends the model's own bytes.
pub(crate) fn encode(
    out: &mut Vec<u8>,
    model_identifier: &str,
    guid: &str,
    layer: &LayerState,
    model: impl FnOnce(&mut Vec<u8>),
) {
    out.extend_from_slice(&MAGIC);
    put_u32(out, FORMAT_VERSION);
    put_str(out, model_identifier);
    put_str(out, guid);
    out.push(layer.call_state.code());
    out.extend_from_slice(&layer.start_time.to_le_bytes());
    put_opt_f64(out, layer.stop_time);
    put_opt_f64(out, layer.tolerance);
    out.extend_from_slice(&layer.time_ns.to_le_bytes());
    out.extend_from_slice(&layer.steps.to_le_bytes());
    let len_at = out.len();
    out.extend_from_slice(&0u64.to_le_bytes());
    let model_start = out.len();
    model(out);
    let model_len = (out.len() - model_start) as u64;
    out[len_at..model_start].copy_from_slice(&model_len.to_le_bytes());
}

struct Reader<'a> {
    bytes: &'a [u8],
    pos: usize,
}

impl<'a> Reader<'a> {
    fn take(&mut self, n: usize, what: &str) -> Result<&'a [u8], String> {
        let end = self.pos.checked_add(n).filter(|&e| e <= self.bytes.len());
        match end {
            Some(end) => {
                let s = &self.bytes[self.pos..end];
                self.pos = end;
                Ok(s)
            }
            None => Err(format!(
                "length mismatch: the state is truncated ({} bytes, {what} needs {n} more at offset {})",
                self.bytes.len(),
                self.pos
            )),
        }
    }

    fn array<const N: usize>(&mut self, what: &str) -> Result<[u8; N], String> {
        let s = self.take(N, what)?;
        let mut a = [0u8; N];
        a.copy_from_slice(s);
        Ok(a)
    }

    fn u32(&mut self, what: &str) -> Result<u32, String> {
        Ok(u32::from_le_bytes(self.array(what)?))
    }

    fn u64(&mut self, what: &str) -> Result<u64, String> {
        Ok(u64::from_le_bytes(self.array(what)?))
    }

    fn f64(&mut self, what: &str) -> Result<f64, String> {
        Ok(f64::from_le_bytes(self.array(what)?))
    }

    fn flag(&mut self, what: &str) -> Result<bool, String> {
        match self.array::<1>(what)?[0] {
            0 => Ok(false),
            1 => Ok(true),
            b => Err(format!(
                "corrupt state: {what} flag is {b}, expected 0 or 1"
            )),
        }
    }

    fn opt_f64(&mut self, what: &str) -> Result<Option<f64>, String> {
        let defined = self.flag(what)?;
        let v = self.f64(what)?;
        Ok(defined.then_some(v))
    }

    fn string(&mut self, what: &str) -> Result<&'a [u8], String> {
        let n = self.u32(what)? as usize;
        self.take(n, what)
    }
}

/// Parses a serialized state, checking magic, version, model identifier, GUID and length.
/// Returns the layer state and the model's bytes.
pub(crate) fn decode<'a>(
    bytes: &'a [u8],
    model_identifier: &str,
    guid: &str,
) -> Result<(LayerState, &'a [u8]), String> {
    let mut r = Reader { bytes, pos: 0 };
    let magic = r.array::<8>("the magic")?;
    if magic != MAGIC {
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
    let id = r.string("the model identifier")?;
    if id != model_identifier.as_bytes() {
        return Err(format!(
            "model identifier mismatch: the state belongs to '{}', this FMU is '{model_identifier}'",
            String::from_utf8_lossy(id)
        ));
    }
    let g = r.string("the GUID")?;
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
    let stop_time = r.opt_f64("the stop time")?;
    let tolerance = r.opt_f64("the tolerance")?;
    let time_ns = i64::from_le_bytes(r.array("the time counter")?);
    let steps = r.u64("the step counter")?;
    let model_len = r.u64("the model state length")?;
    let model_len = usize::try_from(model_len).map_err(|_| {
        format!("length mismatch: model state length {model_len} does not fit in memory")
    })?;
    let model = r.take(model_len, "the model state")?;
    if r.pos != bytes.len() {
        return Err(format!(
            "length mismatch: {} trailing bytes after the model state",
            bytes.len() - r.pos
        ));
    }
    if !start_time.is_finite() || time_ns < 0 {
        return Err(format!(
            "corrupt state: start time {start_time}, time counter {time_ns} ns"
        ));
    }
    Ok((
        LayerState {
            call_state,
            start_time,
            stop_time,
            tolerance,
            time_ns,
            steps,
        },
        model,
    ))
}

#[cfg(test)]
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
        assert!(decode_err(&b[..b.len() - 1]).contains("truncated"));
        let mut t = b.clone();
        t.push(0);
        assert!(decode_err(&t).contains("trailing"));
        assert!(decode_err(&[]).contains("truncated"));
    }
}
