//! The byte-level pieces of a serialized FMU state (FMI 2.0 section 2.1.8,
//! `fmi2SerializeFMUstate`), shared by the layer's own framing ([`crate::serial`]) and by a
//! model's part ([`Fmi2Model::serialize_state`](crate::Fmi2Model::serialize_state)): one
//! place for the layout rules.
//!
//! - Integers and floats little-endian, floats as their IEEE 754 bits (exact round trip);
//!   byte strings and UTF-8 strings with a `u64` length prefix ([`put_bytes`], [`put_str`]).
//! - [`Reader`]: the bounds-checked reader of the same, naming what it was reading when the
//!   bytes run out.
//! - Structured values ([`put_value`], [`Reader::value`]) through serde in MessagePack
//!   (rmp-serde, <https://docs.rs/rmp-serde>; floats as float 64, their bits kept), with
//!   named fields, behind the same length prefix. Every float in a value must be finite, when
//!   it is written and when it is read ([`check_finite`]): an FMU state with a NaN or an
//!   infinity is refused with the path of the value (`plan[2][1] = NaN`).

use serde::de::DeserializeOwned;
use serde::ser::{self, Serialize};
use std::fmt;

/// Appends `v` little-endian.
pub fn put_u64(out: &mut Vec<u8>, v: u64) {
    out.extend_from_slice(&v.to_le_bytes());
}

/// Appends `v` as its IEEE 754 bits, little-endian.
pub fn put_f64(out: &mut Vec<u8>, v: f64) {
    out.extend_from_slice(&v.to_le_bytes());
}

/// Appends `b` with a `u64` length prefix.
pub fn put_bytes(out: &mut Vec<u8>, b: &[u8]) {
    put_u64(out, b.len() as u64);
    out.extend_from_slice(b);
}

/// Appends the UTF-8 bytes of `s` with a `u64` length prefix.
pub fn put_str(out: &mut Vec<u8>, s: &str) {
    put_bytes(out, s.as_bytes());
}

/// Appends a model part's header: its 4-byte magic and its format version (u16), read back
/// by [`Reader::header`].
pub fn put_header(out: &mut Vec<u8>, magic: &[u8; 4], version: u16) {
    out.extend_from_slice(magic);
    out.extend_from_slice(&version.to_le_bytes());
}

/// Appends `value` as MessagePack with named fields, with a `u64` length prefix.
///
/// # Errors
/// A float of `value` that is not finite (named by its path), or a value serde cannot
/// encode.
pub fn put_value<T: Serialize>(out: &mut Vec<u8>, value: &T) -> Result<(), String> {
    check_finite(value)?;
    let bytes = rmp_serde::to_vec_named(value).map_err(|e| format!("cannot encode: {e}"))?;
    put_bytes(out, &bytes);
    Ok(())
}

/// Bounds-checked little-endian reader over a serialized state; every error names `owner`
/// (e.g. `"TowingPlant state"`), what was being read and where.
#[derive(Debug)]
pub struct Reader<'a> {
    bytes: &'a [u8],
    pos: usize,
    owner: &'static str,
}

impl<'a> Reader<'a> {
    /// A reader at the start of `bytes`.
    #[must_use]
    pub fn new(bytes: &'a [u8], owner: &'static str) -> Self {
        Reader {
            bytes,
            pos: 0,
            owner,
        }
    }

    /// The offset of the next byte.
    #[must_use]
    pub fn position(&self) -> usize {
        self.pos
    }

    /// The next `n` bytes.
    ///
    /// # Errors
    /// Fewer than `n` bytes left.
    pub fn take(&mut self, n: usize, what: &str) -> Result<&'a [u8], String> {
        let end = self.pos.checked_add(n).filter(|&e| e <= self.bytes.len());
        let Some(end) = end else {
            return Err(format!(
                "{} is truncated: {what} needs {n} bytes at offset {} of {}",
                self.owner,
                self.pos,
                self.bytes.len()
            ));
        };
        let s = &self.bytes[self.pos..end];
        self.pos = end;
        Ok(s)
    }

    /// Checks a header written by [`put_header`].
    ///
    /// # Errors
    /// Another magic (not a state of this owner) or another format version.
    pub fn header(&mut self, magic: &[u8; 4], version: u16) -> Result<(), String> {
        if self.take(4, "the magic")? != magic {
            return Err(format!("not a {} (wrong magic)", self.owner));
        }
        let found = u16::from_le_bytes(self.array("the format version")?);
        if found != version {
            return Err(format!(
                "{} format version {found} is not supported (this build reads {version})",
                self.owner
            ));
        }
        Ok(())
    }

    /// The next `N` bytes as an array.
    ///
    /// # Errors
    /// As [`take`](Self::take).
    pub fn array<const N: usize>(&mut self, what: &str) -> Result<[u8; N], String> {
        let mut a = [0u8; N];
        a.copy_from_slice(self.take(N, what)?);
        Ok(a)
    }

    /// A little-endian `u32`.
    ///
    /// # Errors
    /// As [`take`](Self::take).
    pub fn u32(&mut self, what: &str) -> Result<u32, String> {
        Ok(u32::from_le_bytes(self.array(what)?))
    }

    /// A little-endian `u64`.
    ///
    /// # Errors
    /// As [`take`](Self::take).
    pub fn u64(&mut self, what: &str) -> Result<u64, String> {
        Ok(u64::from_le_bytes(self.array(what)?))
    }

    /// A little-endian `f64` (its bits; not checked).
    ///
    /// # Errors
    /// As [`take`](Self::take).
    pub fn f64(&mut self, what: &str) -> Result<f64, String> {
        Ok(f64::from_le_bytes(self.array(what)?))
    }

    /// A finite little-endian `f64`.
    ///
    /// # Errors
    /// As [`take`](Self::take); a NaN or an infinity.
    pub fn finite_f64(&mut self, what: &str) -> Result<f64, String> {
        let v = self.f64(what)?;
        if v.is_finite() {
            Ok(v)
        } else {
            Err(format!("{}: {what} = {v} is not finite", self.owner))
        }
    }

    /// A byte 0 or 1.
    ///
    /// # Errors
    /// As [`take`](Self::take); any other byte.
    pub fn flag(&mut self, what: &str) -> Result<bool, String> {
        match self.array::<1>(what)?[0] {
            0 => Ok(false),
            1 => Ok(true),
            b => Err(format!(
                "{}: {what} flag is {b}, expected 0 or 1",
                self.owner
            )),
        }
    }

    /// A byte string with a `u64` length prefix ([`put_bytes`]).
    ///
    /// # Errors
    /// As [`take`](Self::take).
    pub fn bytes(&mut self, what: &str) -> Result<&'a [u8], String> {
        let n = self.u64(what)?;
        let n = usize::try_from(n).map_err(|_| {
            format!(
                "{}: the length {n} of {what} does not fit in memory",
                self.owner
            )
        })?;
        self.take(n, what)
    }

    /// A UTF-8 string with a `u64` length prefix ([`put_str`]).
    ///
    /// # Errors
    /// As [`take`](Self::take); invalid UTF-8.
    pub fn string(&mut self, what: &str) -> Result<String, String> {
        let b = self.bytes(what)?;
        String::from_utf8(b.to_vec())
            .map_err(|_| format!("{}: {what} is not valid UTF-8", self.owner))
    }

    /// A value written by [`put_value`]; every float finite.
    ///
    /// # Errors
    /// As [`take`](Self::take); bytes that do not decode as `T`; a float that is not
    /// finite, named by its path.
    pub fn value<T: DeserializeOwned + Serialize>(&mut self, what: &str) -> Result<T, String> {
        let b = self.bytes(what)?;
        let value: T = rmp_serde::from_slice(b)
            .map_err(|e| format!("{}: {what} does not decode: {e}", self.owner))?;
        check_finite(&value).map_err(|e| format!("{}: {what}: {e}", self.owner))?;
        Ok(value)
    }

    /// Checks that every byte was read.
    ///
    /// # Errors
    /// Trailing bytes.
    pub fn finish(&self) -> Result<(), String> {
        match self.bytes.len() - self.pos {
            0 => Ok(()),
            n => Err(format!("{} has {n} trailing bytes", self.owner)),
        }
    }
}

/// Checks that every float in `value` is finite.
///
/// # Errors
/// The path and value of the first that is not (`plan[2][1] = NaN is not finite`).
pub fn check_finite<T: Serialize + ?Sized>(value: &T) -> Result<(), String> {
    let mut walker = Finite { path: Vec::new() };
    value.serialize(&mut walker).map_err(|e| e.0)
}

/// A step of a path into a value.
enum Step {
    Field(&'static str),
    Index(usize),
}

/// The serializer that only looks at floats (`check_finite`).
struct Finite {
    path: Vec<Step>,
}

/// `check_finite`'s error: the message.
#[derive(Debug)]
struct NotFinite(String);

impl fmt::Display for NotFinite {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(&self.0)
    }
}

impl std::error::Error for NotFinite {}

impl ser::Error for NotFinite {
    fn custom<T: fmt::Display>(msg: T) -> Self {
        NotFinite(msg.to_string())
    }
}

impl Finite {
    fn float(&self, v: f64) -> Result<(), NotFinite> {
        if v.is_finite() {
            return Ok(());
        }
        let mut path = String::new();
        for step in &self.path {
            match step {
                Step::Field(name) if path.is_empty() => path.push_str(name),
                Step::Field(name) => {
                    path.push('.');
                    path.push_str(name);
                }
                Step::Index(i) => path.push_str(&format!("[{i}]")),
            }
        }
        let path = if path.is_empty() { "the value" } else { &path };
        Err(NotFinite(format!("{path} = {v} is not finite")))
    }

    fn nested<T: Serialize + ?Sized>(&mut self, step: Step, v: &T) -> Result<(), NotFinite> {
        self.path.push(step);
        let r = v.serialize(&mut *self);
        self.path.pop();
        r
    }
}

/// Every compound part of [`Finite`]: elements by index, fields by name.
struct Part<'a> {
    walker: &'a mut Finite,
    index: usize,
}

impl<'a> Part<'a> {
    /// The part of a sequence, tuple, map or struct `walker` is entering.
    fn of(walker: &'a mut Finite) -> Part<'a> {
        Part { walker, index: 0 }
    }

    fn element<T: Serialize + ?Sized>(&mut self, v: &T) -> Result<(), NotFinite> {
        let i = self.index;
        self.index += 1;
        self.walker.nested(Step::Index(i), v)
    }
}

macro_rules! elements {
    ($($trait:ident :: $method:ident),*) => {$(
        impl ser::$trait for Part<'_> {
            type Ok = ();
            type Error = NotFinite;
            fn $method<T: Serialize + ?Sized>(&mut self, v: &T) -> Result<(), NotFinite> {
                self.element(v)
            }
            fn end(self) -> Result<(), NotFinite> {
                Ok(())
            }
        }
    )*};
}
elements!(
    SerializeSeq::serialize_element,
    SerializeTuple::serialize_element,
    SerializeTupleStruct::serialize_field,
    SerializeTupleVariant::serialize_field
);

macro_rules! fields {
    ($($trait:ident),*) => {$(
        impl ser::$trait for Part<'_> {
            type Ok = ();
            type Error = NotFinite;
            fn serialize_field<T: Serialize + ?Sized>(
                &mut self,
                key: &'static str,
                v: &T,
            ) -> Result<(), NotFinite> {
                self.walker.nested(Step::Field(key), v)
            }
            fn end(self) -> Result<(), NotFinite> {
                Ok(())
            }
        }
    )*};
}
fields!(SerializeStruct, SerializeStructVariant);

impl ser::SerializeMap for Part<'_> {
    type Ok = ();
    type Error = NotFinite;
    fn serialize_key<T: Serialize + ?Sized>(&mut self, k: &T) -> Result<(), NotFinite> {
        self.element(k)
    }
    fn serialize_value<T: Serialize + ?Sized>(&mut self, v: &T) -> Result<(), NotFinite> {
        self.element(v)
    }
    fn end(self) -> Result<(), NotFinite> {
        Ok(())
    }
}

macro_rules! ignored {
    ($($method:ident($ty:ty)),*) => {$(
        fn $method(self, _: $ty) -> Result<(), NotFinite> {
            Ok(())
        }
    )*};
}

impl<'a> ser::Serializer for &'a mut Finite {
    type Ok = ();
    type Error = NotFinite;
    type SerializeSeq = Part<'a>;
    type SerializeTuple = Part<'a>;
    type SerializeTupleStruct = Part<'a>;
    type SerializeTupleVariant = Part<'a>;
    type SerializeMap = Part<'a>;
    type SerializeStruct = Part<'a>;
    type SerializeStructVariant = Part<'a>;

    ignored!(
        serialize_bool(bool),
        serialize_i8(i8),
        serialize_i16(i16),
        serialize_i32(i32),
        serialize_i64(i64),
        serialize_u8(u8),
        serialize_u16(u16),
        serialize_u32(u32),
        serialize_u64(u64),
        serialize_char(char),
        serialize_str(&str),
        serialize_bytes(&[u8]),
        serialize_unit_struct(&'static str)
    );

    fn serialize_f32(self, v: f32) -> Result<(), NotFinite> {
        self.float(f64::from(v))
    }
    fn serialize_f64(self, v: f64) -> Result<(), NotFinite> {
        self.float(v)
    }
    fn serialize_none(self) -> Result<(), NotFinite> {
        Ok(())
    }
    fn serialize_some<T: Serialize + ?Sized>(self, v: &T) -> Result<(), NotFinite> {
        v.serialize(self)
    }
    fn serialize_unit(self) -> Result<(), NotFinite> {
        Ok(())
    }
    fn serialize_unit_variant(
        self,
        _: &'static str,
        _: u32,
        _: &'static str,
    ) -> Result<(), NotFinite> {
        Ok(())
    }
    fn serialize_newtype_struct<T: Serialize + ?Sized>(
        self,
        _: &'static str,
        v: &T,
    ) -> Result<(), NotFinite> {
        v.serialize(self)
    }
    fn serialize_newtype_variant<T: Serialize + ?Sized>(
        self,
        _: &'static str,
        _: u32,
        variant: &'static str,
        v: &T,
    ) -> Result<(), NotFinite> {
        self.nested(Step::Field(variant), v)
    }
    fn serialize_seq(self, _: Option<usize>) -> Result<Part<'a>, NotFinite> {
        Ok(Part::of(self))
    }
    fn serialize_tuple(self, _: usize) -> Result<Part<'a>, NotFinite> {
        Ok(Part::of(self))
    }
    fn serialize_tuple_struct(self, _: &'static str, _: usize) -> Result<Part<'a>, NotFinite> {
        Ok(Part::of(self))
    }
    fn serialize_tuple_variant(
        self,
        _: &'static str,
        _: u32,
        _: &'static str,
        _: usize,
    ) -> Result<Part<'a>, NotFinite> {
        Ok(Part::of(self))
    }
    fn serialize_map(self, _: Option<usize>) -> Result<Part<'a>, NotFinite> {
        Ok(Part::of(self))
    }
    fn serialize_struct(self, _: &'static str, _: usize) -> Result<Part<'a>, NotFinite> {
        Ok(Part::of(self))
    }
    fn serialize_struct_variant(
        self,
        _: &'static str,
        _: u32,
        _: &'static str,
        _: usize,
    ) -> Result<Part<'a>, NotFinite> {
        Ok(Part::of(self))
    }
}

#[cfg(test)]
#[allow(clippy::unwrap_used)]
mod tests {
    use super::*;
    use serde::{Deserialize, Serialize};

    #[derive(Debug, PartialEq, Serialize, Deserialize)]
    struct Inner {
        plan: [[f64; 2]; 3],
        anchor: Option<f64>,
    }

    #[derive(Debug, PartialEq, Serialize, Deserialize)]
    enum Kind {
        A(Inner),
        B,
    }

    #[derive(Debug, PartialEq, Serialize, Deserialize)]
    struct Outer {
        name: String,
        kind: Kind,
        list: Vec<f64>,
    }

    fn sample() -> Outer {
        Outer {
            name: "x".into(),
            kind: Kind::A(Inner {
                plan: [[0.1, -0.0], [f64::MIN_POSITIVE, 1e308], [5e-324, -3.5]],
                anchor: Some(std::f64::consts::PI),
            }),
            list: vec![1.0 / 3.0],
        }
    }

    #[test]
    fn values_round_trip_bit_for_bit() {
        let mut out = Vec::new();
        put_value(&mut out, &sample()).unwrap();
        put_str(&mut out, "tail");
        let mut r = Reader::new(&out, "test state");
        let back: Outer = r.value("the value").unwrap();
        assert_eq!(r.string("the tail").unwrap(), "tail");
        r.finish().unwrap();
        let Kind::A(a) = &back.kind else {
            panic!("wrong variant")
        };
        let bits = |p: &[[f64; 2]; 3]| p.map(|r| r.map(f64::to_bits));
        let Kind::A(s) = sample().kind else {
            panic!("wrong variant")
        };
        assert_eq!(bits(&a.plan), bits(&s.plan));
        assert_eq!(back, sample());
    }

    #[test]
    fn a_non_finite_float_is_named_by_its_path() {
        let mut v = sample();
        if let Kind::A(a) = &mut v.kind {
            a.plan[2][1] = f64::NAN;
        }
        let mut out = Vec::new();
        let e = put_value(&mut out, &v).unwrap_err();
        assert_eq!(e, "kind.A.plan[2][1] = NaN is not finite");
        v.kind = Kind::B;
        v.list.push(f64::NEG_INFINITY);
        assert_eq!(
            check_finite(&v).unwrap_err(),
            "list[1] = -inf is not finite"
        );
        // Written without the check, refused when read.
        let bytes = rmp_serde::to_vec_named(&v).unwrap();
        let mut framed = Vec::new();
        put_bytes(&mut framed, &bytes);
        let e = Reader::new(&framed, "test state")
            .value::<Outer>("the value")
            .unwrap_err();
        assert_eq!(e, "test state: the value: list[1] = -inf is not finite");
    }

    #[test]
    fn truncation_and_trailing_bytes_are_named() {
        let mut out = Vec::new();
        put_str(&mut out, "abc");
        let mut r = Reader::new(&out[..out.len() - 1], "test state");
        let e = r.string("the name").unwrap_err();
        assert!(
            e.starts_with("test state is truncated: the name needs 3 bytes"),
            "{e}"
        );
        out.push(0);
        let mut r = Reader::new(&out, "test state");
        r.string("the name").unwrap();
        assert_eq!(r.finish().unwrap_err(), "test state has 1 trailing bytes");
        let mut r = Reader::new(&[2], "test state");
        assert_eq!(
            r.flag("the switch").unwrap_err(),
            "test state: the switch flag is 2, expected 0 or 1"
        );
    }
}
