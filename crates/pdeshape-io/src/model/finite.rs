//! Finds the first non-finite number anywhere in a serialisable value (a report): its
//! path as `check --json` would spell it, e.g. `patches[0].fill.g1_radians`.
//!
//! The report is written as JSON, where NaN and ±inf become `null` and look like a section
//! that does not apply; this walk sees the numbers themselves. It is a [`serde::Serializer`]
//! that writes nothing: it follows every struct field, sequence element, map value and
//! option, and stops at the first `f64`/`f32` that is not finite.

use serde::Serialize;
use serde::ser::{self, Impossible};
use std::fmt;

/// The path of the first non-finite number in `value`, or `None` when every number is
/// finite.
///
/// ```
/// #[derive(serde::Serialize)]
/// struct R { a: f64, b: Vec<Option<f64>> }
/// use pdeshape_io::model::first_non_finite;
/// assert_eq!(first_non_finite(&R { a: 1.0, b: vec![None, Some(2.0)] }), None);
/// assert_eq!(first_non_finite(&R { a: 1.0, b: vec![None, Some(f64::NAN)] }).as_deref(), Some("b[1]"));
/// ```
pub fn first_non_finite<T: Serialize + ?Sized>(value: &T) -> Option<String> {
    let mut w = Walk { path: Vec::new() };
    match value.serialize(&mut w) {
        Err(Found(p)) => Some(p),
        Ok(()) => None,
    }
}

/// The path of the non-finite number (the walk's "error").
#[derive(Debug)]
struct Found(String);

impl fmt::Display for Found {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(&self.0)
    }
}

impl std::error::Error for Found {}

impl ser::Error for Found {
    fn custom<T: fmt::Display>(msg: T) -> Self {
        Found(format!("(not serialisable: {msg})"))
    }
}

/// One step of a path.
enum Step {
    Field(&'static str),
    Key(String),
    Index(usize),
}

struct Walk {
    path: Vec<Step>,
}

impl Walk {
    fn here(&self) -> String {
        let mut s = String::new();
        for step in &self.path {
            match step {
                Step::Field(f) => {
                    if !s.is_empty() {
                        s.push('.');
                    }
                    s.push_str(f);
                }
                Step::Key(k) => {
                    if !s.is_empty() {
                        s.push('.');
                    }
                    s.push_str(k);
                }
                Step::Index(i) => s.push_str(&format!("[{i}]")),
            }
        }
        s
    }

    fn float(&self, x: f64) -> Result<(), Found> {
        if x.is_finite() { Ok(()) } else { Err(Found(self.here())) }
    }

    fn nested<T: Serialize + ?Sized>(&mut self, step: Step, v: &T) -> Result<(), Found> {
        self.path.push(step);
        let r = v.serialize(&mut *self);
        self.path.pop();
        r
    }
}

/// A compound value being walked: counts its elements for the index steps.
struct Compound<'a> {
    walk: &'a mut Walk,
    index: usize,
    key: Option<String>,
}

/// Serializer methods for values that hold no float: nothing to look at.
macro_rules! ignored {
    ($($name:ident: $ty:ty,)*) => {
        $(fn $name(self, _: $ty) -> Result<(), Found> {
            Ok(())
        })*
    };
}

impl<'a> ser::Serializer for &'a mut Walk {
    type Ok = ();
    type Error = Found;
    type SerializeSeq = Compound<'a>;
    type SerializeTuple = Compound<'a>;
    type SerializeTupleStruct = Compound<'a>;
    type SerializeTupleVariant = Compound<'a>;
    type SerializeMap = Compound<'a>;
    type SerializeStruct = Compound<'a>;
    type SerializeStructVariant = Compound<'a>;

    fn serialize_f64(self, v: f64) -> Result<(), Found> {
        self.float(v)
    }
    fn serialize_f32(self, v: f32) -> Result<(), Found> {
        self.float(f64::from(v))
    }
    ignored! {
        serialize_bool: bool,
        serialize_i8: i8,
        serialize_i16: i16,
        serialize_i32: i32,
        serialize_i64: i64,
        serialize_u8: u8,
        serialize_u16: u16,
        serialize_u32: u32,
        serialize_u64: u64,
        serialize_char: char,
        serialize_str: &str,
        serialize_bytes: &[u8],
    }
    fn serialize_none(self) -> Result<(), Found> {
        Ok(())
    }
    fn serialize_some<T: Serialize + ?Sized>(self, v: &T) -> Result<(), Found> {
        v.serialize(self)
    }
    fn serialize_unit(self) -> Result<(), Found> {
        Ok(())
    }
    fn serialize_unit_struct(self, _: &'static str) -> Result<(), Found> {
        Ok(())
    }
    fn serialize_unit_variant(self, _: &'static str, _: u32, _: &'static str) -> Result<(), Found> {
        Ok(())
    }
    fn serialize_newtype_struct<T: Serialize + ?Sized>(self, _: &'static str, v: &T) -> Result<(), Found> {
        v.serialize(self)
    }
    fn serialize_newtype_variant<T: Serialize + ?Sized>(
        self,
        _: &'static str,
        _: u32,
        variant: &'static str,
        v: &T,
    ) -> Result<(), Found> {
        self.nested(Step::Field(variant), v)
    }
    fn serialize_seq(self, _: Option<usize>) -> Result<Compound<'a>, Found> {
        Ok(Compound { walk: self, index: 0, key: None })
    }
    fn serialize_tuple(self, _: usize) -> Result<Compound<'a>, Found> {
        Ok(Compound { walk: self, index: 0, key: None })
    }
    fn serialize_tuple_struct(self, _: &'static str, _: usize) -> Result<Compound<'a>, Found> {
        Ok(Compound { walk: self, index: 0, key: None })
    }
    fn serialize_tuple_variant(
        self,
        _: &'static str,
        _: u32,
        _: &'static str,
        _: usize,
    ) -> Result<Compound<'a>, Found> {
        Ok(Compound { walk: self, index: 0, key: None })
    }
    fn serialize_map(self, _: Option<usize>) -> Result<Compound<'a>, Found> {
        Ok(Compound { walk: self, index: 0, key: None })
    }
    fn serialize_struct(self, _: &'static str, _: usize) -> Result<Compound<'a>, Found> {
        Ok(Compound { walk: self, index: 0, key: None })
    }
    fn serialize_struct_variant(
        self,
        _: &'static str,
        _: u32,
        _: &'static str,
        _: usize,
    ) -> Result<Compound<'a>, Found> {
        Ok(Compound { walk: self, index: 0, key: None })
    }
}

impl Compound<'_> {
    fn element<T: Serialize + ?Sized>(&mut self, v: &T) -> Result<(), Found> {
        let i = self.index;
        self.index += 1;
        self.walk.nested(Step::Index(i), v)
    }
}

macro_rules! elements {
    ($($trait:ident :: $method:ident),*) => {$(
        impl ser::$trait for Compound<'_> {
            type Ok = ();
            type Error = Found;
            fn $method<T: Serialize + ?Sized>(&mut self, v: &T) -> Result<(), Found> {
                self.element(v)
            }
            fn end(self) -> Result<(), Found> {
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
        impl ser::$trait for Compound<'_> {
            type Ok = ();
            type Error = Found;
            fn serialize_field<T: Serialize + ?Sized>(&mut self, key: &'static str, v: &T) -> Result<(), Found> {
                self.walk.nested(Step::Field(key), v)
            }
            fn end(self) -> Result<(), Found> {
                Ok(())
            }
        }
    )*};
}
fields!(SerializeStruct, SerializeStructVariant);

impl ser::SerializeMap for Compound<'_> {
    type Ok = ();
    type Error = Found;
    fn serialize_key<T: Serialize + ?Sized>(&mut self, key: &T) -> Result<(), Found> {
        // keys are strings (names) in the reports; anything else is shown by its index
        self.key = Some(key.serialize(KeyName).unwrap_or_else(|_| format!("[{}]", self.index)));
        Ok(())
    }
    fn serialize_value<T: Serialize + ?Sized>(&mut self, v: &T) -> Result<(), Found> {
        let key = self.key.take().unwrap_or_default();
        self.index += 1;
        self.walk.nested(Step::Key(key), v)
    }
    fn end(self) -> Result<(), Found> {
        Ok(())
    }
}

/// A map key as text (string keys only).
struct KeyName;

impl ser::Serializer for KeyName {
    type Ok = String;
    type Error = Found;
    type SerializeSeq = Impossible<String, Found>;
    type SerializeTuple = Impossible<String, Found>;
    type SerializeTupleStruct = Impossible<String, Found>;
    type SerializeTupleVariant = Impossible<String, Found>;
    type SerializeMap = Impossible<String, Found>;
    type SerializeStruct = Impossible<String, Found>;
    type SerializeStructVariant = Impossible<String, Found>;

    fn serialize_str(self, v: &str) -> Result<String, Found> {
        Ok(v.to_string())
    }
    fn serialize_bool(self, v: bool) -> Result<String, Found> {
        Ok(v.to_string())
    }
    fn serialize_i8(self, v: i8) -> Result<String, Found> {
        Ok(v.to_string())
    }
    fn serialize_i16(self, v: i16) -> Result<String, Found> {
        Ok(v.to_string())
    }
    fn serialize_i32(self, v: i32) -> Result<String, Found> {
        Ok(v.to_string())
    }
    fn serialize_i64(self, v: i64) -> Result<String, Found> {
        Ok(v.to_string())
    }
    fn serialize_u8(self, v: u8) -> Result<String, Found> {
        Ok(v.to_string())
    }
    fn serialize_u16(self, v: u16) -> Result<String, Found> {
        Ok(v.to_string())
    }
    fn serialize_u32(self, v: u32) -> Result<String, Found> {
        Ok(v.to_string())
    }
    fn serialize_u64(self, v: u64) -> Result<String, Found> {
        Ok(v.to_string())
    }
    fn serialize_f32(self, v: f32) -> Result<String, Found> {
        Ok(v.to_string())
    }
    fn serialize_f64(self, v: f64) -> Result<String, Found> {
        Ok(v.to_string())
    }
    fn serialize_char(self, v: char) -> Result<String, Found> {
        Ok(v.to_string())
    }
    fn serialize_bytes(self, _: &[u8]) -> Result<String, Found> {
        Err(Found(String::new()))
    }
    fn serialize_none(self) -> Result<String, Found> {
        Err(Found(String::new()))
    }
    fn serialize_some<T: Serialize + ?Sized>(self, v: &T) -> Result<String, Found> {
        v.serialize(self)
    }
    fn serialize_unit(self) -> Result<String, Found> {
        Err(Found(String::new()))
    }
    fn serialize_unit_struct(self, name: &'static str) -> Result<String, Found> {
        Ok(name.to_string())
    }
    fn serialize_unit_variant(self, _: &'static str, _: u32, variant: &'static str) -> Result<String, Found> {
        Ok(variant.to_string())
    }
    fn serialize_newtype_struct<T: Serialize + ?Sized>(self, _: &'static str, v: &T) -> Result<String, Found> {
        v.serialize(self)
    }
    fn serialize_newtype_variant<T: Serialize + ?Sized>(
        self,
        _: &'static str,
        _: u32,
        _: &'static str,
        _: &T,
    ) -> Result<String, Found> {
        Err(Found(String::new()))
    }
    fn serialize_seq(self, _: Option<usize>) -> Result<Self::SerializeSeq, Found> {
        Err(Found(String::new()))
    }
    fn serialize_tuple(self, _: usize) -> Result<Self::SerializeTuple, Found> {
        Err(Found(String::new()))
    }
    fn serialize_tuple_struct(self, _: &'static str, _: usize) -> Result<Self::SerializeTupleStruct, Found> {
        Err(Found(String::new()))
    }
    fn serialize_tuple_variant(
        self,
        _: &'static str,
        _: u32,
        _: &'static str,
        _: usize,
    ) -> Result<Self::SerializeTupleVariant, Found> {
        Err(Found(String::new()))
    }
    fn serialize_map(self, _: Option<usize>) -> Result<Self::SerializeMap, Found> {
        Err(Found(String::new()))
    }
    fn serialize_struct(self, _: &'static str, _: usize) -> Result<Self::SerializeStruct, Found> {
        Err(Found(String::new()))
    }
    fn serialize_struct_variant(
        self,
        _: &'static str,
        _: u32,
        _: &'static str,
        _: usize,
    ) -> Result<Self::SerializeStructVariant, Found> {
        Err(Found(String::new()))
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::collections::BTreeMap;

    #[derive(Serialize)]
    struct Inner {
        x: f32,
        pair: (f64, f64),
    }

    #[derive(Serialize)]
    enum Kind {
        A { value: f64 },
    }

    #[derive(Serialize)]
    struct Outer {
        name: String,
        inner: Vec<Inner>,
        by_name: BTreeMap<String, Option<f64>>,
        kind: Kind,
    }

    fn outer() -> Outer {
        Outer {
            name: "p".into(),
            inner: vec![Inner { x: 1.0, pair: (0.0, 2.0) }, Inner { x: 3.0, pair: (4.0, 5.0) }],
            by_name: [("a".to_string(), None), ("b".to_string(), Some(1.0))].into_iter().collect(),
            kind: Kind::A { value: 0.5 },
        }
    }

    #[test]
    fn every_place_a_number_can_hide_is_visited() {
        assert_eq!(first_non_finite(&outer()), None);
        let mut o = outer();
        o.inner[1].pair.1 = f64::INFINITY;
        assert_eq!(first_non_finite(&o).as_deref(), Some("inner[1].pair[1]"));
        let mut o = outer();
        o.inner[0].x = f32::NAN;
        assert_eq!(first_non_finite(&o).as_deref(), Some("inner[0].x"));
        let mut o = outer();
        o.by_name.insert("b".into(), Some(f64::NEG_INFINITY));
        assert_eq!(first_non_finite(&o).as_deref(), Some("by_name.b"));
        let mut o = outer();
        o.kind = Kind::A { value: f64::NAN };
        assert_eq!(first_non_finite(&o).as_deref(), Some("kind.value"));
    }
}
