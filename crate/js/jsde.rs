//! Reads JS values into Rust types through serde, remembering the path of the field that failed
//! (`modes[0].frequencyHz`).
//!
//! This is serde-wasm-bindgen 0.6.5's `Deserializer` with serde_path_to_error 0.1.20's path
//! tracking folded in: the same conversions, the same error messages and the same paths, but one
//! deserializer type instead of a tracking wrapper around another, so every serde visitor is
//! instantiated once (the wrapper doubled the generated code; see docs/page-performance.md).
//! The path is kept on a stack: a segment is pushed while a sequence element or a map value is
//! read, and the first (deepest) failing read records the stack, as path_to_error's `Track` does.

use js_sys::{Array, ArrayBuffer, JsString, Map, Number, Object, Symbol, Uint8Array};
use serde::de::{self, DeserializeOwned, DeserializeSeed, Visitor};
use serde_wasm_bindgen::Error;
use std::cell::RefCell;
use std::fmt::Write;
use wasm_bindgen::{JsCast, JsValue};

type Result<T> = std::result::Result<T, Error>;

#[cfg(test)]
mod differential;

#[wasm_bindgen::prelude::wasm_bindgen]
extern "C" {
    /// `Object.entries(object)`, its exception caught: a getter or a Proxy trap may throw
    /// (issue 21), which is then an error of the value, not an exception through the module.
    #[wasm_bindgen(catch, js_namespace = Object, js_name = entries)]
    fn try_entries(object: &JsValue) -> std::result::Result<Array, JsValue>;
}

/// [`try_entries`], a throw reported as an error of the value.
fn entries_of(object: &JsValue) -> Result<Array> {
    try_entries(object).map_err(|_| threw())
}

/// The error of a value whose reading threw.
#[cold]
fn threw() -> Error {
    de::Error::custom("could not be read (a getter or a Proxy trap threw)")
}

/// One step of the path: an element index, a map key (or enum variant), or a non-string key.
enum Segment {
    Index(usize),
    Key(String),
    Unknown,
}

thread_local! {
    static PATH: RefCell<Vec<Segment>> = const { RefCell::new(Vec::new()) };
    static FAILED: RefCell<Option<String>> = const { RefCell::new(None) };
}

fn push(segment: Segment) {
    PATH.with(|p| p.borrow_mut().push(segment));
}

fn pop() {
    PATH.with(|p| {
        p.borrow_mut().pop();
    });
}

/// Formats the current path as serde_path_to_error's `Path` displays it.
fn path_string() -> String {
    PATH.with(|p| {
        let p = p.borrow();
        if p.is_empty() {
            return ".".to_string();
        }
        let mut out = String::new();
        let mut separator = "";
        for segment in p.iter() {
            match segment {
                Segment::Index(i) => {
                    let _ = write!(out, "[{i}]");
                }
                Segment::Key(k) => {
                    out.push_str(separator);
                    out.push_str(k);
                }
                Segment::Unknown => {
                    out.push_str(separator);
                    out.push('?');
                }
            }
            separator = ".";
        }
        out
    })
}

/// Records the current path if no deeper failure has been recorded yet.
#[cold]
fn note(error: Error) -> Error {
    FAILED.with(|f| {
        let mut f = f.borrow_mut();
        if f.is_none() {
            *f = Some(path_string());
        }
    });
    error
}

/// Deserializes `value`; on failure, returns the path of the failing field (`.` for the value
/// itself, as serde_path_to_error prints it) and the error.
///
/// `Debug`: in the crate's tests every read is also made by upstream serde-wasm-bindgen with
/// serde_path_to_error and by this reader with serde's own tagged-enum parser, and the three
/// compared ([`differential`]).
pub(crate) fn deserialize<T: DeserializeOwned + std::fmt::Debug>(
    value: JsValue,
) -> std::result::Result<T, (String, Error)> {
    #[cfg(not(test))]
    {
        fork(value)
    }
    #[cfg(test)]
    {
        let upstream = differential::upstream::<T>(&value);
        let buffered = differential::buffered(|| fork::<T>(value.clone()));
        let read = fork::<T>(value.clone());
        differential::compare(
            core::any::type_name::<T>(),
            &value,
            upstream,
            buffered,
            &read,
        );
        read
    }
}

/// [`deserialize`] by the fork alone.
fn fork<T: DeserializeOwned>(value: JsValue) -> std::result::Result<T, (String, Error)> {
    #[cfg(feature = "any-deserializer")]
    crate::tagged::JS_READER.get_or_init(core::any::type_name::<De>);
    PATH.with(|p| p.borrow_mut().clear());
    FAILED.with(|f| *f.borrow_mut() = None);
    T::deserialize(De::new(value, true)).map_err(|e| {
        let path = FAILED
            .with(|f| f.borrow_mut().take())
            .unwrap_or_else(|| ".".to_string());
        (path, e)
    })
}

/// Reads `segment`'s value with `f`, recording the path including `segment` on failure.
fn within<T>(segment: Segment, f: impl FnOnce() -> Result<T>) -> Result<T> {
    push(segment);
    let r = f().map_err(note);
    pop();
    r
}

/// Records the current path followed by `segment` (if nothing deeper was recorded).
#[cold]
fn fail_at(segment: Segment, error: Error) -> Error {
    push(segment);
    let error = note(error);
    pop();
    error
}

fn key_segment(key: &Option<String>) -> Segment {
    match key {
        Some(k) => Segment::Key(k.clone()),
        None => Segment::Unknown,
    }
}

/// Elements of a JS array (by index, as js_sys's `ArrayIter`) or of any JS iterator.
enum SeqAccess {
    Array {
        array: Array,
        next: u32,
        len: u32,
    },
    Iter(js_sys::IntoIter, usize),
    /// One value `left` more times, read at the current path ([`crate::tagged::SAME`]).
    Same {
        value: JsValue,
        left: usize,
    },
}

/// The longest sequence (array, typed array or iterable) read from JS: the longest array an
/// export's own arguments take ([`super::args::MAX_ARRAY_LENGTH`], 2²⁶). Longer is an error of
/// that field before any element is read: the one difference from serde-wasm-bindgen, which
/// reads until memory runs out.
pub(crate) const MAX_SEQUENCE_LENGTH: usize = super::args::MAX_ARRAY_LENGTH;

/// What [`check_length`]'s error expects.
const TOO_LONG: &str = "at most 67108864 elements";
const _: () = assert!(MAX_SEQUENCE_LENGTH == 67_108_864);

/// [`MAX_SEQUENCE_LENGTH`], checked on a sequence's length before it is read.
fn check_length(length: f64) -> Result<()> {
    if length > MAX_SEQUENCE_LENGTH as f64 {
        return Err(note(de::Error::invalid_length(
            length.min(u64::MAX as f64) as usize,
            &TOO_LONG,
        )));
    }
    Ok(())
}

impl SeqAccess {
    fn array(array: Array) -> Self {
        let len = array.length();
        SeqAccess::Array {
            array,
            next: 0,
            len,
        }
    }
}

impl<'de> de::SeqAccess<'de> for SeqAccess {
    type Error = Error;

    fn next_element_seed<T: DeserializeSeed<'de>>(&mut self, seed: T) -> Result<Option<T::Value>> {
        let (value, index) = match self {
            SeqAccess::Array { array, next, len } => {
                if *next >= *len {
                    return Ok(None);
                }
                let value = array.get(*next);
                *next += 1;
                (value, *next as usize - 1)
            }
            SeqAccess::Same { value, left } => {
                if *left == 0 {
                    return Ok(None);
                }
                *left -= 1;
                return seed.deserialize(De::new(value.clone(), true)).map(Some);
            }
            SeqAccess::Iter(_, next) if *next >= MAX_SEQUENCE_LENGTH => {
                // An endless iterable (a generator) stops here, not at memory's end.
                return Err(de::Error::invalid_length(*next + 1, &TOO_LONG));
            }
            SeqAccess::Iter(iter, next) => match iter.next() {
                None => return Ok(None),
                Some(Err(e)) => return Err(note(Error::from(e))),
                Some(Ok(value)) => {
                    *next += 1;
                    (value, *next - 1)
                }
            },
        };
        within(Segment::Index(index), || {
            seed.deserialize(De::new(value, true)).map(Some)
        })
    }

    fn size_hint(&self) -> Option<usize> {
        match self {
            SeqAccess::Array { next, len, .. } => Some((*len - *next) as usize),
            SeqAccess::Iter(..) => None,
            SeqAccess::Same { left, .. } => Some(*left),
        }
    }
}

/// Entries of a map: `[key, value]` pairs of a JS iterator (a `Map`), `Object.entries` of a
/// plain object, or the declared fields of a struct read from an object (in declaration order,
/// missing ones skipped, as serde-wasm-bindgen's `ObjectAccess`).
enum MapSource {
    Iter(js_sys::IntoIter),
    Entries {
        entries: Array,
        next: u32,
        len: u32,
    },
    Fields {
        object: Object,
        fields: std::slice::Iter<'static, &'static str>,
    },
}

struct MapAccess {
    source: MapSource,
    key: Option<String>,
    value: Option<JsValue>,
}

impl MapAccess {
    fn new(source: MapSource) -> Self {
        MapAccess {
            source,
            key: None,
            value: None,
        }
    }
}

/// The next key of a map: a declared field of a struct, or a key read from JS.
enum Key {
    Field(&'static str),
    Js(JsValue),
}

impl MapAccess {
    /// Moves to the next entry: keeps its value (and its key as text, for the path) and returns
    /// its key, or `None` at the end. Not generic, so each visitor's `next_key_seed` is only
    /// the key's own reading (this was ~0.7 KB of wasm per struct type).
    #[inline(never)]
    fn advance(&mut self) -> Result<Option<Key>> {
        self.key = None;
        let key = match &mut self.source {
            MapSource::Iter(iter) => match iter.next() {
                None => return Ok(None),
                Some(Err(e)) => return Err(fail_at(Segment::Unknown, Error::from(e))),
                Some(Ok(pair)) => {
                    // Not `[key, value]`: `null[0]` would throw through the module
                    // (serde-wasm-bindgen's `convert_pair` lets it: `[null]` read where a
                    // struct with a flattened part goes, through serde's buffered parser).
                    if pair.loose_eq(&JsValue::NULL) {
                        let e =
                            de::Error::invalid_type(de::Unexpected::Unit, &"a [key, value] pair");
                        return Err(fail_at(Segment::Unknown, e));
                    }
                    let (key, value) = convert_pair(pair);
                    self.value = Some(value);
                    key
                }
            },
            MapSource::Entries { entries, next, len } => {
                if *next >= *len {
                    return Ok(None);
                }
                let (key, value) = convert_pair(entries.get(*next));
                *next += 1;
                self.value = Some(value);
                key
            }
            MapSource::Fields { object, fields } => {
                let mut found = None;
                for field in fields.by_ref() {
                    let js_field = JsValue::from(JsString::from(*field));
                    // A getter or a Proxy trap that throws: an error of that field (not a
                    // missing field, nor an exception through the module).
                    let throws = |_| fail_at(Segment::Key(field.to_string()), threw());
                    let value = js_sys::Reflect::get(object, &js_field).map_err(throws)?;
                    // `undefined` may be a missing field: check with `in`.
                    let missing = value.is_undefined()
                        && !js_sys::Reflect::has(object, &js_field).map_err(throws)?;
                    if !missing {
                        found = Some((*field, value));
                        break;
                    }
                }
                let Some((field, value)) = found else {
                    return Ok(None);
                };
                self.value = Some(value);
                self.key = Some(field.to_string());
                return Ok(Some(Key::Field(field)));
            }
        };
        self.key = key.as_string();
        Ok(Some(Key::Js(key)))
    }
}

fn convert_pair(pair: JsValue) -> (JsValue, JsValue) {
    let pair = pair.unchecked_into::<Array>();
    (pair.get(0), pair.get(1))
}

impl<'de> de::MapAccess<'de> for MapAccess {
    type Error = Error;

    fn next_key_seed<K: DeserializeSeed<'de>>(&mut self, seed: K) -> Result<Option<K::Value>> {
        let r = match self.advance()? {
            None => return Ok(None),
            Some(Key::Field(field)) => {
                let key: de::value::StrDeserializer<Error> =
                    de::IntoDeserializer::into_deserializer(field);
                seed.deserialize(key)
            }
            Some(Key::Js(key)) => seed.deserialize(De::new(key, false)),
        };
        match r {
            Ok(k) => Ok(Some(k)),
            Err(e) => Err(fail_at(key_segment(&self.key), e)),
        }
    }

    fn next_value_seed<V: DeserializeSeed<'de>>(&mut self, seed: V) -> Result<V::Value> {
        let value = self.value.take().unwrap_or_default();
        let segment = key_segment(&self.key.take());
        within(segment, || seed.deserialize(De::new(value, true)))
    }

    fn size_hint(&self) -> Option<usize> {
        match &self.source {
            MapSource::Entries { next, len, .. } => Some((*len - *next) as usize),
            MapSource::Iter(_) => None,
            MapSource::Fields { fields, .. } => Some(fields.len()),
        }
    }
}

/// An enum as serde-json writes it: `"Variant"` or `{ Variant: payload }`; or, with
/// `tag_field`, internally tagged: `{ [tag_field]: "variant", …fields }` ([`crate::tagged`]),
/// the payload being the object itself.
struct EnumAccess {
    tag: JsValue,
    payload: JsValue,
    tag_field: Option<&'static str>,
}

impl<'de> de::EnumAccess<'de> for EnumAccess {
    type Error = Error;
    type Variant = VariantAccess;

    fn variant_seed<V: DeserializeSeed<'de>>(self, seed: V) -> Result<(V::Value, VariantAccess)> {
        if let Some(field) = self.tag_field {
            // A bad tag is reported at the tag's field (`shapers[0].family`).
            let v = seed
                .deserialize(De::new(self.tag, false))
                .map_err(|e| fail_at(Segment::Key(field.to_string()), e))?;
            return Ok((
                v,
                VariantAccess {
                    payload: self.payload,
                    variant: None,
                    tagged: true,
                },
            ));
        }
        let variant = self.tag.as_string();
        let v = seed.deserialize(De::new(self.tag, false)).map_err(note)?;
        Ok((
            v,
            VariantAccess {
                payload: self.payload,
                variant,
                tagged: false,
            },
        ))
    }
}

/// An internally tagged variant (`tagged`) reads its fields from the tagged object itself, at
/// the object's path; an externally tagged one from the payload, under the variant's name.
struct VariantAccess {
    payload: JsValue,
    variant: Option<String>,
    tagged: bool,
}

impl VariantAccess {
    fn read<T>(self, f: impl FnOnce(De) -> Result<T>) -> Result<T> {
        let payload = De::new(self.payload, true);
        if self.tagged {
            f(payload)
        } else {
            within(key_segment(&self.variant), || f(payload))
        }
    }
}

impl<'de> de::VariantAccess<'de> for VariantAccess {
    type Error = Error;

    fn unit_variant(self) -> Result<()> {
        if self.tagged {
            // The object's other fields are ignored, as serde's internally tagged enums do.
            return Ok(());
        }
        let payload = self.payload;
        within(key_segment(&self.variant), || {
            de::Deserialize::deserialize(De::new(payload, false))
        })
    }

    fn newtype_variant_seed<T: DeserializeSeed<'de>>(self, seed: T) -> Result<T::Value> {
        self.read(|payload| seed.deserialize(payload))
    }

    fn tuple_variant<V: Visitor<'de>>(self, len: usize, visitor: V) -> Result<V::Value> {
        self.read(|payload| de::Deserializer::deserialize_tuple(payload, len, visitor))
    }

    fn struct_variant<V: Visitor<'de>>(
        self,
        fields: &'static [&'static str],
        visitor: V,
    ) -> Result<V::Value> {
        self.read(|payload| de::Deserializer::deserialize_struct(payload, "", fields, visitor))
    }
}

/// A JS value as a serde `Deserializer`. `track`: whether a failure records the path (map keys
/// and enum tags are read untracked, as path_to_error reads them).
pub(crate) struct De {
    value: JsValue,
    track: bool,
}

impl De {
    fn new(value: JsValue, track: bool) -> Self {
        De { value, track }
    }

    fn done<T>(&self, r: Result<T>) -> Result<T> {
        if self.track {
            r.map_err(note)
        } else {
            r
        }
    }

    fn is_nullish(&self) -> bool {
        self.value.loose_eq(&JsValue::NULL)
    }

    fn as_bytes(&self) -> Option<Vec<u8>> {
        let temp;
        let v = if let Some(v) = self.value.dyn_ref::<Uint8Array>() {
            v
        } else if let Some(v) = self.value.dyn_ref::<ArrayBuffer>() {
            temp = Uint8Array::new(v);
            &temp
        } else {
            return None;
        };
        Some(v.to_vec())
    }

    /// The error for a value of the wrong type. Unlike serde-wasm-bindgen, which formats
    /// anything else with `{:?}` (the whole of an array: seconds for a sparse
    /// `new Array(2 ** 27)`) and copies binary data to say "byte array", this names what the
    /// value is ([`super::args::describe`]) and quotes at most 40 characters of a string, so
    /// that the error costs the same whatever was passed (issue 21).
    #[cold]
    fn invalid_type_(&self, visitor: &dyn de::Expected) -> Error {
        let string: String;
        let unexpected = if self.is_nullish() {
            de::Unexpected::Unit
        } else if let Some(v) = self.value.as_bool() {
            de::Unexpected::Bool(v)
        } else if let Some(v) = self.value.as_f64() {
            de::Unexpected::Float(v)
        } else if let Some(v) = self.value.dyn_ref::<JsString>() {
            string = if v.length() > 40 {
                format!("{}…", String::from(v.slice(0, 40)))
            } else {
                String::from(v)
            };
            de::Unexpected::Str(&string)
        } else if self.value.is_instance_of::<Uint8Array>()
            || self.value.is_instance_of::<ArrayBuffer>()
        {
            de::Unexpected::Other("byte array")
        } else {
            de::Unexpected::Other(super::args::describe(&self.value))
        };
        de::Error::invalid_type(unexpected, visitor)
    }

    fn invalid_type<'de, V: Visitor<'de>>(&self, visitor: V) -> Result<V::Value> {
        Err(self.invalid_type_(&visitor))
    }

    fn as_safe_integer(&self) -> Option<i64> {
        if Number::is_safe_integer(&self.value) {
            return Some(self.value.unchecked_into_f64() as i64);
        }
        None
    }

    fn signed<'de, V: Visitor<'de>>(&self, visitor: V) -> Result<V::Value> {
        match self.as_safe_integer() {
            Some(v) => visitor.visit_i64(v),
            _ => self.invalid_type(visitor),
        }
    }

    fn unsigned<'de, V: Visitor<'de>>(&self, visitor: V) -> Result<V::Value> {
        match self.as_safe_integer() {
            Some(v) if v >= 0 => visitor.visit_u64(v as _),
            _ => self.invalid_type(visitor),
        }
    }

    fn any<'de, V: Visitor<'de>>(self, visitor: V) -> Result<V::Value> {
        if self.is_nullish() {
            visitor.visit_unit()
        } else if let Some(v) = self.value.as_bool() {
            visitor.visit_bool(v)
        } else if self.value.is_bigint() {
            match i64::try_from(self.value) {
                Ok(v) => visitor.visit_i64(v),
                Err(value) => match u64::try_from(value) {
                    Ok(v) => visitor.visit_u64(v),
                    Err(_) => Err(de::Error::custom("Couldn't deserialize i64 or u64 from a BigInt outside i64::MIN..u64::MAX bounds")),
                },
            }
        } else if let Some(v) = self.value.as_f64() {
            if Number::is_safe_integer(&self.value) {
                visitor.visit_i64(v as i64)
            } else {
                visitor.visit_f64(v)
            }
        } else if let Some(v) = self.value.as_string() {
            visitor.visit_string(v)
        } else if Array::is_array(&self.value) {
            self.seq(visitor)
        } else if let Some(bytes) = self.as_bytes() {
            visitor.visit_byte_buf(bytes)
        } else if self.value.is_object() && {
            // `Symbol.iterator in value`, a Proxy's `has` trap's throw caught.
            let iterable = js_sys::Reflect::has(&self.value, Symbol::iterator().as_ref())
                .map_err(|_| threw())?;
            !iterable || self.value.has_type::<Map>()
        } {
            self.map(visitor)
        } else {
            self.invalid_type(visitor)
        }
    }

    fn seq<'de, V: Visitor<'de>>(self, visitor: V) -> Result<V::Value> {
        if let Some(arr) = self.value.dyn_ref::<Array>() {
            check_length(arr.length() as f64)?;
            visitor.visit_seq(SeqAccess::array(arr.clone()))
        } else if !self.value.is_object() {
            // Not asked for its `Symbol.iterator`: `Reflect.get` throws on a number or a string
            // (serde-wasm-bindgen reports that `TypeError` as the error).
            self.invalid_type(visitor)
        } else if let Some(iter) = js_sys::try_iter(&self.value)? {
            if ArrayBuffer::is_view(&self.value) {
                // A typed array's `length`, read before its elements are: 2²⁶ + 1 of them would
                // otherwise grow a `Vec` to a gigabyte, which a browser's wasm memory may refuse
                // (an abort: a trap, found by the 10⁶-call boundary profile in Chromium).
                let length = js_sys::Reflect::get(&self.value, &JsValue::from_str("length"))
                    .ok()
                    .and_then(|l| l.as_f64())
                    .unwrap_or(0.0);
                check_length(length)?;
            }
            visitor.visit_seq(SeqAccess::Iter(iter, 0))
        } else {
            self.invalid_type(visitor)
        }
    }

    fn map<'de, V: Visitor<'de>>(self, visitor: V) -> Result<V::Value> {
        if !self.value.is_object() {
            // As in `seq`: not a `TypeError` from `Reflect.get` on a primitive.
            return self.invalid_type(visitor);
        }
        match js_sys::try_iter(&self.value)? {
            Some(iter) => visitor.visit_map(MapAccess::new(MapSource::Iter(iter))),
            None => {
                if self.value.is_object() {
                    let entries = entries_of(&self.value)?;
                    let len = entries.length();
                    visitor.visit_map(MapAccess::new(MapSource::Entries {
                        entries,
                        next: 0,
                        len,
                    }))
                } else {
                    self.invalid_type(visitor)
                }
            }
        }
    }

    fn string<'de, V: Visitor<'de>>(self, visitor: V) -> Result<V::Value> {
        if let Some(v) = self.value.as_string() {
            visitor.visit_string(v)
        } else {
            self.invalid_type(visitor)
        }
    }

    fn bigint_i64<'de, V: Visitor<'de>>(self, visitor: V) -> Result<V::Value> {
        if self.value.is_bigint() {
            match i64::try_from(self.value) {
                Ok(v) => visitor.visit_i64(v),
                Err(_) => Err(de::Error::custom(
                    "Couldn't deserialize i64 from a BigInt outside i64::MIN..i64::MAX bounds",
                )),
            }
        } else {
            self.signed(visitor)
        }
    }

    fn bigint_u64<'de, V: Visitor<'de>>(self, visitor: V) -> Result<V::Value> {
        if self.value.is_bigint() {
            match u64::try_from(self.value) {
                Ok(v) => visitor.visit_u64(v),
                Err(_) => Err(de::Error::custom(
                    "Couldn't deserialize u64 from a BigInt outside u64::MIN..u64::MAX bounds",
                )),
            }
        } else {
            self.unsigned(visitor)
        }
    }

    /// `{ [field]: "variant", …fields }` ([`crate::tagged`]): the tag is read first, the
    /// variant's fields from the same object.
    fn tagged_enum<'de, V: Visitor<'de>>(
        self,
        field: &'static str,
        visitor: V,
    ) -> Result<V::Value> {
        if !self.value.is_object() {
            return self.invalid_type(visitor);
        }
        let key = JsValue::from_str(field);
        let tag = js_sys::Reflect::get(&self.value, &key).map_err(|_| threw())?;
        if tag.is_undefined() && !js_sys::Reflect::has(&self.value, &key).map_err(|_| threw())? {
            return Err(de::Error::missing_field(field));
        }
        visitor.visit_enum(EnumAccess {
            tag,
            payload: self.value,
            tag_field: Some(field),
        })
    }

    fn enum_<'de, V: Visitor<'de>>(self, visitor: V) -> Result<V::Value> {
        let access = if self.value.is_string() {
            EnumAccess {
                tag: self.value,
                payload: JsValue::UNDEFINED,
                tag_field: None,
            }
        } else if self.value.is_object()
            // Not `Object.entries` of a typed array: one entry per element, 2^26 of them for
            // a long signal (issue 21's fuzz: gigabytes for `firmware: new Float32Array(…)`).
            && !ArrayBuffer::is_view(&self.value)
        {
            let entries = entries_of(&self.value)?;
            if entries.length() != 1 {
                return Err(de::Error::invalid_length(entries.length() as _, &"1"));
            }
            let (tag, payload) = convert_pair(entries.get(0));
            EnumAccess {
                tag,
                payload,
                tag_field: None,
            }
        } else {
            return self.invalid_type(visitor);
        };
        visitor.visit_enum(access)
    }

    fn byte_buf<'de, V: Visitor<'de>>(self, visitor: V) -> Result<V::Value> {
        if let Some(bytes) = self.as_bytes() {
            visitor.visit_byte_buf(bytes)
        } else if let Some(arr) = self.value.dyn_ref::<Array>() {
            visitor.visit_seq(SeqAccess::array(arr.clone()))
        } else {
            self.invalid_type(visitor)
        }
    }
}

macro_rules! forward {
    ($($name:ident => $method:ident),* $(,)?) => {
        $(
            fn $name<V: Visitor<'de>>(self, visitor: V) -> Result<V::Value> {
                let track = self.track;
                let r = self.$method(visitor);
                if track { r.map_err(note) } else { r }
            }
        )*
    };
}

impl<'de> de::Deserializer<'de> for De {
    type Error = Error;

    forward! {
        deserialize_any => any,
        deserialize_seq => seq,
        deserialize_map => map,
        deserialize_identifier => string,
        deserialize_str => string,
        deserialize_string => string,
        deserialize_i8 => signed_owned,
        deserialize_i16 => signed_owned,
        deserialize_i32 => signed_owned,
        deserialize_u8 => unsigned_owned,
        deserialize_u16 => unsigned_owned,
        deserialize_u32 => unsigned_owned,
        deserialize_i64 => bigint_i64,
        deserialize_u64 => bigint_u64,
        deserialize_bytes => byte_buf,
        deserialize_byte_buf => byte_buf,
        deserialize_f32 => f64_,
        deserialize_f64 => f64_,
        deserialize_unit => unit,
        deserialize_bool => bool_,
        deserialize_i128 => i128_,
        deserialize_u128 => u128_,
        deserialize_char => char_,
        deserialize_option => option,
    }

    fn deserialize_unit_struct<V: Visitor<'de>>(
        self,
        _name: &'static str,
        visitor: V,
    ) -> Result<V::Value> {
        self.deserialize_unit(visitor)
    }

    fn deserialize_newtype_struct<V: Visitor<'de>>(
        self,
        _name: &'static str,
        visitor: V,
    ) -> Result<V::Value> {
        let track = self.track;
        let r = visitor.visit_newtype_struct(self);
        if track {
            r.map_err(note)
        } else {
            r
        }
    }

    fn deserialize_tuple<V: Visitor<'de>>(self, _len: usize, visitor: V) -> Result<V::Value> {
        self.deserialize_seq(visitor)
    }

    fn deserialize_tuple_struct<V: Visitor<'de>>(
        self,
        name: &'static str,
        len: usize,
        visitor: V,
    ) -> Result<V::Value> {
        if name == crate::tagged::SAME {
            let r = if self.value.is_object() {
                visitor.visit_seq(SeqAccess::Same {
                    value: self.value.clone(),
                    left: len,
                })
            } else {
                self.invalid_type(visitor)
            };
            return self.done(r);
        }
        self.deserialize_seq(visitor)
    }

    fn deserialize_struct<V: Visitor<'de>>(
        self,
        _name: &'static str,
        fields: &'static [&'static str],
        visitor: V,
    ) -> Result<V::Value> {
        let r = if self.value.is_object() {
            let object = self.value.clone().unchecked_into::<Object>();
            visitor.visit_map(MapAccess::new(MapSource::Fields {
                object,
                fields: fields.iter(),
            }))
        } else {
            self.invalid_type(visitor)
        };
        self.done(r)
    }

    fn deserialize_enum<V: Visitor<'de>>(
        self,
        name: &'static str,
        variants: &'static [&'static str],
        visitor: V,
    ) -> Result<V::Value> {
        let track = self.track;
        let r = match variants.first() {
            Some(field) if name == crate::tagged::TAGGED => self.tagged_enum(field, visitor),
            _ => self.enum_(visitor),
        };
        if track {
            r.map_err(note)
        } else {
            r
        }
    }

    fn deserialize_ignored_any<V: Visitor<'de>>(self, visitor: V) -> Result<V::Value> {
        visitor.visit_unit()
    }

    fn is_human_readable(&self) -> bool {
        true
    }
}

impl De {
    fn signed_owned<'de, V: Visitor<'de>>(self, visitor: V) -> Result<V::Value> {
        self.signed(visitor)
    }

    fn unsigned_owned<'de, V: Visitor<'de>>(self, visitor: V) -> Result<V::Value> {
        self.unsigned(visitor)
    }

    fn f64_<'de, V: Visitor<'de>>(self, visitor: V) -> Result<V::Value> {
        if let Some(v) = self.value.as_f64() {
            visitor.visit_f64(v)
        } else {
            self.invalid_type(visitor)
        }
    }

    fn unit<'de, V: Visitor<'de>>(self, visitor: V) -> Result<V::Value> {
        if self.is_nullish() {
            visitor.visit_unit()
        } else {
            self.invalid_type(visitor)
        }
    }

    fn bool_<'de, V: Visitor<'de>>(self, visitor: V) -> Result<V::Value> {
        if let Some(v) = self.value.as_bool() {
            visitor.visit_bool(v)
        } else {
            self.invalid_type(visitor)
        }
    }

    fn i128_<'de, V: Visitor<'de>>(self, visitor: V) -> Result<V::Value> {
        if self.value.is_bigint() {
            match i128::try_from(self.value) {
                Ok(v) => visitor.visit_i128(v),
                Err(_) => Err(de::Error::custom(
                    "Couldn't deserialize i128 from a BigInt outside i128::MIN..i128::MAX bounds",
                )),
            }
        } else {
            self.invalid_type(visitor)
        }
    }

    fn u128_<'de, V: Visitor<'de>>(self, visitor: V) -> Result<V::Value> {
        if self.value.is_bigint() {
            match u128::try_from(self.value) {
                Ok(v) => visitor.visit_u128(v),
                Err(_) => Err(de::Error::custom(
                    "Couldn't deserialize u128 from a BigInt outside u128::MIN..u128::MAX bounds",
                )),
            }
        } else {
            self.invalid_type(visitor)
        }
    }

    fn char_<'de, V: Visitor<'de>>(self, visitor: V) -> Result<V::Value> {
        if let Some(s) = self.value.dyn_ref::<JsString>() {
            if let Some(c) = s.as_char() {
                return visitor.visit_char(c);
            }
        }
        self.invalid_type(visitor)
    }

    fn option<'de, V: Visitor<'de>>(self, visitor: V) -> Result<V::Value> {
        if !self.is_nullish() {
            visitor.visit_some(self)
        } else {
            visitor.visit_none()
        }
    }
}
