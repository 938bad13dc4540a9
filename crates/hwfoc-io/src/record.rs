//! The record of `docs/RECORD-SCHEMA.md` ([`hwfoc_records::record`]), its columns seen by this
//! crate's writers: [`Column`] and [`Visitor`] here know how every writer stores each column's
//! values (`write/stored.rs`).

pub use hwfoc_records::record::*;

pub use crate::write::stored::{Column, Visitor, columns};
