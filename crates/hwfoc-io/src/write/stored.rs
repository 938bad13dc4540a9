//! The columns as this crate's writers see them: each value type stored by Arrow
//! ([`ArrowValue`]) and Parquet ([`ParquetValue`]) as well as written as text, and the walk
//! through the columns in schema order with those traits known ([`visit`]). The record's own
//! [`Visitor`](hwfoc_records::record::Visitor) knows only the text encodings: the binary
//! writers' traits live here, above the record.

use hwfoc_records::record::{Cons, Nil, Value};

use super::arrow::ArrowValue;
use super::parquet::ParquetValue;

/// A value type every writer stores.
pub trait StoredValue: Value + ArrowValue + ParquetValue {}

impl<T: Value + ArrowValue + ParquetValue> StoredValue for T {}

/// A column whose values every writer stores: each column of the record schema
/// ([`hwfoc_records::record::Column`]).
pub trait Column: hwfoc_records::record::Column<Value: StoredValue> {}

impl<C: hwfoc_records::record::Column<Value: StoredValue>> Column for C {}

/// Something a writer does for each column, in schema order: [`visit`] calls
/// [`Visitor::column`] once per column, with the column's type, monomorphised and inlined.
pub trait Visitor {
    /// Called for column `C`.
    fn column<C: Column>(&mut self);
}

/// A list of columns walked in order.
pub trait Walk {
    /// Calls `visitor` for each column of the list, in order.
    fn walk<V: Visitor>(visitor: &mut V);
}

impl Walk for Nil {
    #[inline(always)]
    fn walk<V: Visitor>(_: &mut V) {}
}

impl<C: Column, Rest: Walk> Walk for Cons<C, Rest> {
    #[inline(always)]
    fn walk<V: Visitor>(visitor: &mut V) {
        visitor.column::<C>();
        Rest::walk(visitor);
    }
}

/// Calls `visitor` for each column, in schema order.
#[inline(always)]
pub fn visit<V: Visitor>(visitor: &mut V) {
    <columns::List as Walk>::walk(visitor);
}

/// The columns of the schema ([`hwfoc_records::record::columns`]), walked by this crate's
/// writers with [`visit`].
pub mod columns {
    pub use super::visit;
    pub use hwfoc_records::record::columns::*;
}
