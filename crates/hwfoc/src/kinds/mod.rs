//! One module per frame kind, each a type implementing [`FrameKind`](crate::FrameKind) with one
//! arm in [`Frame`](crate::Frame).
//!
//! | module | type | header | length | check bytes |
//! |---|---|---|---|---|
//! | [`data`] | [`DataFrame`](data::DataFrame) | `9B 16 01 02` | 24 | 16-bit sum, low byte first |
//! | [`info`] | [`InfoFrame`](info::InfoFrame) | `9B 4C 01 01` | 77 | low byte of the 16-bit sum |
//!
//! A kind's module holds everything particular to it (layout, constants, field accessors,
//! conversions) and nothing the other kinds share: that is in [`crate::wire`]. How to add a kind
//! is described in [`crate::frame`].

pub mod data;
pub mod info;
