//! Internally tagged enums (`{ family: "zvd", … }`, `{ kind: "step", … }`) read without serde's
//! buffering.
//!
//! serde's derived `#[serde(tag = "…")]` reads the whole object into its in-memory `Content`
//! tree first (the tag may come last), then reads the variant again from that tree; a
//! `#[serde(flatten)]` field does the same for its whole struct. In the wasm that second
//! deserializer compiled every variant's parser a second time, about a tenth of the code. A JS
//! object needs no buffering: the tag is one property read. So on a JS value (the JS boundary's reader)
//! the tag is read first and the variant's fields from the same object; from any other
//! deserializer (serde_json in the tests, for instance) serde's derived impl reads it as before.
//!
//! [`tagged_enum!`] declares such an enum once. It derives `Serialize` with the tag on the enum
//! itself, and `Deserialize` on two private copies: an externally tagged one, which the JS
//! deserializer hands the tag as the variant name, and an internally tagged one for the rest.

use serde::de::{self, Deserialize, Deserializer, EnumAccess, SeqAccess, Visitor};
use std::fmt;
use std::marker::PhantomData;

/// The enum name the JS deserializer treats as "internally tagged": `variants[0]` names the tag
/// property, the variant's fields come from the same object.
pub(crate) const TAGGED: &str = "\0input-shaping tagged enum";

/// The tuple-struct name the JS deserializer treats as "the same value, `len` times": a struct
/// with a flattened enum reads its own fields and then the enum from one object.
pub(crate) const SAME: &str = "\0input-shaping same value";

/// The type name of the JS deserializer, which registers it here before its first read
/// (`js::jsde::deserialize`). The reader sits at the top (the JS boundary) and this module at
/// the ground, so the reader names itself rather than this module naming the reader.
#[cfg(all(target_arch = "wasm32", feature = "any-deserializer"))]
pub(crate) static JS_READER: std::sync::OnceLock<&'static str> = std::sync::OnceLock::new();

/// Whether `D` is the JS deserializer (the type [`JS_READER`] names; no JS read yet, no JS
/// deserializer). Asked at run time, so it cannot leave the other branch
/// out of the wasm: where a value may only come from JS (the wasm without the
/// `any-deserializer` feature, on by default and off in the page's build), the fallback is
/// compiled out instead (`#[cfg]` in [`deserialize`] and [`deserialize_flat`]), or serde's
/// buffering would come back whole.
#[cfg(any(not(target_arch = "wasm32"), feature = "any-deserializer"))]
#[inline(always)]
#[cfg_attr(
    not(target_arch = "wasm32"),
    allow(clippy::extra_unused_type_parameters)
)]
pub(crate) fn is_js<'de, D: Deserializer<'de>>() -> bool {
    #[cfg(target_arch = "wasm32")]
    {
        #[cfg(test)]
        if BUFFERED.load(std::sync::atomic::Ordering::Relaxed) {
            return false;
        }
        JS_READER
            .get()
            .is_some_and(|name| *name == core::any::type_name::<D>())
    }
    #[cfg(not(target_arch = "wasm32"))]
    {
        false
    }
}

/// In the crate's tests, whether the JS reader reads tagged specs through serde's buffered parser
/// (as any other deserializer does), so that the differential test of `js::jsde` can compare the
/// tag-first reading with serde's own on the same values.
#[cfg(all(test, target_arch = "wasm32"))]
pub(crate) static BUFFERED: std::sync::atomic::AtomicBool =
    std::sync::atomic::AtomicBool::new(false);

struct External<E, T> {
    expecting: &'static str,
    marker: PhantomData<fn() -> (E, T)>,
}

impl<'de, E: Deserialize<'de> + Into<T>, T> Visitor<'de> for External<E, T> {
    type Value = T;

    fn expecting(&self, f: &mut fmt::Formatter) -> fmt::Result {
        f.write_str(self.expecting)
    }

    fn visit_enum<A: EnumAccess<'de>>(self, access: A) -> Result<T, A::Error> {
        E::deserialize(de::value::EnumAccessDeserializer::new(access)).map(Into::into)
    }
}

/// Reads an internally tagged enum `T`: through its externally tagged copy `E` from a JS
/// value, through its internally tagged copy `I` from anything else (see [`is_js`]).
/// `tag` is `[tag name]`.
#[cfg_attr(
    all(target_arch = "wasm32", not(feature = "any-deserializer")),
    allow(clippy::extra_unused_type_parameters)
)]
pub(crate) fn deserialize<'de, D, E, I, T>(
    deserializer: D,
    tag: &'static [&'static str],
    expecting: &'static str,
) -> Result<T, D::Error>
where
    D: Deserializer<'de>,
    E: Deserialize<'de> + Into<T>,
    I: Deserialize<'de> + Into<T>,
{
    #[cfg(any(not(target_arch = "wasm32"), feature = "any-deserializer"))]
    if !is_js::<D>() {
        return I::deserialize(deserializer).map(Into::into);
    }
    let visitor = External::<E, T> {
        expecting,
        marker: PhantomData,
    };
    deserializer.deserialize_enum(TAGGED, tag, visitor)
}

struct Pair<A, B>(&'static str, PhantomData<fn() -> (A, B)>);

impl<'de, A: Deserialize<'de>, B: Deserialize<'de>> Visitor<'de> for Pair<A, B> {
    type Value = (A, B);

    fn expecting(&self, f: &mut fmt::Formatter) -> fmt::Result {
        f.write_str(self.0)
    }

    fn visit_seq<S: SeqAccess<'de>>(self, mut seq: S) -> Result<(A, B), S::Error> {
        let a = seq
            .next_element()?
            .ok_or_else(|| de::Error::invalid_length(0, &self))?;
        let b = seq
            .next_element()?
            .ok_or_else(|| de::Error::invalid_length(1, &self))?;
        Ok((a, b))
    }
}

/// Reads a struct with one flattened field as `(A, B)`: from a JS value, `A` the struct's own
/// fields and `B` the flattened one, both from the same object (no buffering); from anything
/// else (see [`is_js`]), through `fallback`, serde's `#[serde(flatten)]` on a copy of the
/// struct.
#[cfg_attr(
    all(target_arch = "wasm32", not(feature = "any-deserializer")),
    allow(unused_variables)
)]
pub(crate) fn deserialize_flat<'de, D, A, B>(
    deserializer: D,
    expecting: &'static str,
    fallback: impl FnOnce(D) -> Result<(A, B), D::Error>,
) -> Result<(A, B), D::Error>
where
    D: Deserializer<'de>,
    A: Deserialize<'de>,
    B: Deserialize<'de>,
{
    #[cfg(any(not(target_arch = "wasm32"), feature = "any-deserializer"))]
    if !is_js::<D>() {
        return fallback(deserializer);
    }
    deserializer.deserialize_tuple_struct(SAME, 2, Pair::<A, B>(expecting, PhantomData))
}

/// Declares an internally tagged enum (see the module docs):
///
/// ```ignore
/// tagged_enum! {
///     tag = "kind", rename_all = "camelCase", mirror = command_spec_serde;
///     /// docs
///     #[derive(Debug, Clone, PartialEq)]
///     pub enum CommandSpec { Step { … }, Profile(ProfileSpec), … }
/// }
/// ```
///
/// The enum gets `Serialize` (with the tag) and `Deserialize`; `mirror` names the private
/// module holding the two copies. Variant and field attributes (`#[serde(default)]`, docs)
/// apply to all three.
macro_rules! tagged_enum {
    (
        tag = $tag:literal, rename_all = $rename:literal, mirror = $mirror:ident;
        $(#[$meta:meta])*
        $vis:vis enum $name:ident {
            $(
                $(#[$vmeta:meta])*
                $variant:ident
                $( { $( $(#[$fmeta:meta])* $field:ident : $fty:ty ),* $(,)? } )?
                $( ( $nty:ty ) )?
            ),* $(,)?
        }
    ) => {
        $(#[$meta])*
        #[derive(serde::Serialize)]
        #[serde(tag = $tag, rename_all = $rename)]
        $vis enum $name {
            $(
                $(#[$vmeta])*
                $variant $( { $( $(#[$fmeta])* $field : $fty ),* } )? $( ( $nty ) )?
            ),*
        }

        #[doc(hidden)]
        mod $mirror {
            pub(super) mod external {
                #[allow(unused_imports)]
                use super::super::*;
                #[derive(serde::Deserialize)]
                #[serde(rename_all = $rename)]
                pub(in super::super) enum $name {
                    $(
                        $(#[$vmeta])*
                        $variant $( { $( $(#[$fmeta])* $field : $fty ),* } )? $( ( $nty ) )?
                    ),*
                }
            }
            pub(super) mod internal {
                #[allow(unused_imports)]
                use super::super::*;
                #[derive(serde::Deserialize)]
                #[serde(tag = $tag, rename_all = $rename)]
                pub(in super::super) enum $name {
                    $(
                        $(#[$vmeta])*
                        $variant $( { $( $(#[$fmeta])* $field : $fty ),* } )? $( ( $nty ) )?
                    ),*
                }
            }
        }

        impl From<$mirror::external::$name> for $name {
            fn from(m: $mirror::external::$name) -> Self {
                match m {
                    $(
                        $mirror::external::$name::$variant
                            $( { $( $field ),* } )? $( ( $crate::tagged::tagged_enum!(@bind $nty, x) ) )?
                            => $name::$variant
                            $( { $( $field ),* } )? $( ( $crate::tagged::tagged_enum!(@bind $nty, x) ) )?,
                    )*
                }
            }
        }

        impl From<$mirror::internal::$name> for $name {
            fn from(m: $mirror::internal::$name) -> Self {
                match m {
                    $(
                        $mirror::internal::$name::$variant
                            $( { $( $field ),* } )? $( ( $crate::tagged::tagged_enum!(@bind $nty, x) ) )?
                            => $name::$variant
                            $( { $( $field ),* } )? $( ( $crate::tagged::tagged_enum!(@bind $nty, x) ) )?,
                    )*
                }
            }
        }

        impl<'de> serde::Deserialize<'de> for $name {
            fn deserialize<D: serde::Deserializer<'de>>(d: D) -> ::core::result::Result<Self, D::Error> {
                $crate::tagged::deserialize::<D, $mirror::external::$name, $mirror::internal::$name, Self>(
                    d,
                    &[$tag],
                    concat!("internally tagged enum ", stringify!($name)),
                )
            }
        }
    };
    (@bind $t:ty, $x:ident) => {
        $x
    };
}
pub(crate) use tagged_enum;
