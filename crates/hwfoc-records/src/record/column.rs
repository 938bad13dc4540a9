//! What a column is ([`Column`]), what its values may be ([`Value`]), how writers go through
//! the columns ([`Visitor`]), and the `columns!` macro that turns the table of
//! [`columns`](super::columns) into all of these.

use hwfoc::telemetry::Data;
use hwfoc::{Protocol, Settings, Status};

use super::Record;
use super::text::TextValue;

/// One column of the record schema: a zero-sized type per column, made by the table in
/// [`columns`](super::columns). Everything here is known at compile time, so a writer generic
/// over the column (see [`Visitor`]) compiles to the code it would have with the column
/// written out by hand.
pub trait Column: 'static {
    /// The column's name (the JSON key, the CSV header, the Arrow and Parquet field name).
    const NAME: &'static str;
    /// Its unit (`-` for a number without unit): in the Arrow field's metadata, key `unit`.
    const UNIT: &'static str;
    /// Its position in the schema, from 0.
    const INDEX: usize;
    /// Whether its values may be null (they are `Option`s).
    const NULLABLE: bool = <Self::Value as Value>::NULLABLE;
    /// `,"NAME":`, the text before its value in a JSON object (the first column's comma becomes
    /// the opening brace).
    const JSON_KEY: &'static str;
    /// Whether JSON Lines and CSV write the column (all but `time`, the binary formats' typed
    /// copy of `t_s`).
    const TEXT: bool = <Self::Value as TextValue>::WRITTEN;
    /// Whether a cached [`TextEncoder`](super::TextEncoder) keeps the text of its values, keyed
    /// by [`Column::text_key`].
    const TEXT_CACHED: bool;

    /// The type of its values, which says how they are stored in each format.
    type Value: Value;

    /// The value of a data frame received at `t_s` from ESC `esc`, under `settings`.
    fn from_frame(t_s: Option<f64>, esc: u8, frame: &Data, settings: &Settings) -> Self::Value;

    /// The value in a record (a field of [`Record`], or derived from one).
    fn from_record(record: &Record) -> Self::Value;

    /// The raw integer of `frame` that the value is computed from, under fixed settings (the
    /// text cache's key; meaningful only where [`Column::TEXT_CACHED`]). The key is the raw
    /// integer alone: every supported protocol that carries the column's quantity converts it
    /// alike under given settings (a protocol that converts one otherwise must key on it too).
    fn text_key(frame: &Data) -> u32;
}

/// A type a column's values may have: `f32`, `Option<f32>`, `Option<f64>`, `u8`, `u16`, `u32`,
/// [`Status`] (an unsigned 16-bit word) and [`FaultList`].
///
/// Each format says how it stores such a value: text (JSON and CSV, `TextValue`), and the
/// binary writers of `hwfoc-io` (Arrow: type, arrays; Parquet: physical type, levels), which
/// implement their own traits for these types. A new value type implements them all; a new
/// column of an existing value type needs none of it.
pub trait Value: Copy + PartialEq + std::fmt::Debug + TextValue {
    /// Whether a value may be null (an `Option`).
    const NULLABLE: bool;
}

/// Value types that are never null.
macro_rules! not_null {
    ($($t:ty),*) => {
        $(impl Value for $t {
            const NULLABLE: bool = false;
        })*
    };
}

not_null!(f32, f64, u8, u16, u32, Status, Protocol, FaultList, UtcTime);

impl<T: Value> Value for Option<T> {
    const NULLABLE: bool = true;
}

/// A list of column types, in schema order ([`columns::List`](super::columns::List)): its first
/// column and the rest. A writer outside this crate walks it with bounds of its own on the
/// columns' value types (its traits for storing them), where [`Visitor`] knows only [`Value`].
pub struct Cons<C, Rest>(std::marker::PhantomData<(C, Rest)>);

/// The end of a [`Cons`] list.
pub struct Nil;

/// The `time` column's value: a receive time as whole microseconds since the Unix epoch, UTC
/// (an Arrow `Timestamp(Microsecond, "UTC")`, a Parquet `TIMESTAMP(MICROS, UTC)`).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct UtcTime(pub i64);

impl UtcTime {
    /// The instant of `t_s`, Unix time in seconds, to the microsecond (as
    /// [`iso8601_us`](crate::time::iso8601_us) writes it); `None` where it has none.
    #[inline(always)]
    pub fn from_seconds(t_s: Option<f64>) -> Option<UtcTime> {
        t_s.and_then(crate::time::unix_us).map(UtcTime)
    }
}

/// Something done for each column, in schema order: [`visit`](super::columns::visit) calls
/// [`Visitor::column`] once per column, with the column's type, so the call is monomorphised
/// and inlined (no dispatch at run time).
pub trait Visitor {
    /// Called for column `C`.
    fn column<C: Column>(&mut self);
}

/// The `faults` column's value: the names of the flags set in a fault word of a protocol, in
/// bit order (a list of strings; in CSV joined by `|`): HW-FOC's and DataLink's status word,
/// HW5's fault byte ([`Protocol::fault_name`]).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct FaultList(pub Status, pub Protocol);

impl FaultList {
    /// The names of the set flags, in bit order.
    pub fn names(self) -> impl ExactSizeIterator<Item = &'static str> {
        let mut names = [""; 16];
        let mut n = 0;
        for name in self.1.fault_names(self.0) {
            names[n] = name;
            n += 1;
        }
        names.into_iter().take(n)
    }
}

/// Declares the columns of the record schema, once each (see [`columns`](super::columns)):
/// makes a zero-sized type per column implementing [`Column`], the [`Record`] struct (a field
/// per column that is not derived from another), `Record::new`, [`COLUMNS`](super::COLUMNS),
/// [`UNITS`](super::UNITS), [`COUNT`](super::columns::COUNT) and
/// [`visit`](super::columns::visit).
///
/// An entry: doc comment, `name: ValueType, "unit", |t_s, esc, frame, settings| value`, then
/// optionally `, text key |frame| raw` (a raw integer of the frame the value is a function of,
/// for the text cache), and `, record |record| value` for a column that is derived from
/// other fields of [`Record`] instead of being one.
macro_rules! columns {
    (
        $(
            $(#[doc = $doc:literal])*
            $name:ident: $value:ty, $unit:literal,
            |$t:pat_param, $e:pat_param, $f:pat_param, $s:pat_param| $from:expr
            $(, text key |$kf:pat_param| $key:expr)?
            $(, record |$r:pat_param| $get:expr)?
            ;
        )*
    ) => {
        /// Column positions, counted by the compiler.
        #[allow(non_camel_case_types)]
        enum Index {
            $($name,)*
        }

        $(
            $(#[doc = $doc])*
            #[doc = ""]
            #[doc = concat!("Unit: `", $unit, "`.")]
            #[allow(non_camel_case_types)]
            #[derive(Debug)]
            pub enum $name {}

            impl $crate::record::Column for $name {
                const NAME: &'static str = stringify!($name);
                const UNIT: &'static str = $unit;
                const INDEX: usize = Index::$name as usize;
                const JSON_KEY: &'static str = concat!(",\"", stringify!($name), "\":");
                const TEXT_CACHED: bool = columns!(@cached $($key)?);
                type Value = $value;

                #[inline(always)]
                fn from_frame(
                    $t: Option<f64>,
                    $e: u8,
                    $f: &hwfoc::telemetry::Data,
                    $s: &hwfoc::Settings,
                ) -> $value {
                    $from
                }

                #[inline(always)]
                fn from_record(record: &$crate::record::Record) -> $value {
                    columns!(@get record, $name $(, |$r| $get)?)
                }

                #[inline(always)]
                fn text_key(frame: &hwfoc::telemetry::Data) -> u32 {
                    columns!(@key frame $(, |$kf| $key)?)
                }
            }
        )*

        /// Number of columns.
        pub const COUNT: usize = [$(stringify!($name)),*].len();

        /// Column names in schema order.
        pub const COLUMNS: [&str; COUNT] = [$(stringify!($name)),*];

        /// Unit of each column, in schema order (`-` for a number without unit).
        pub const UNITS: [&str; COUNT] = [$($unit),*];

        /// Whether JSON Lines and CSV write each column ([`Column::TEXT`](crate::record::Column::TEXT)).
        const TEXT: [bool; COUNT] = [$(<$name as $crate::record::Column>::TEXT),*];

        /// Number of columns JSON Lines and CSV write.
        const TEXT_COUNT: usize = {
            let mut n = 0;
            let mut i = 0;
            while i < COUNT {
                n += TEXT[i] as usize;
                i += 1;
            }
            n
        };

        /// Names of the columns JSON Lines and CSV write, in schema order: the CSV header.
        pub const TEXT_COLUMNS: [&str; TEXT_COUNT] = {
            let mut names = [""; TEXT_COUNT];
            let (mut i, mut n) = (0, 0);
            while i < COUNT {
                if TEXT[i] {
                    names[n] = COLUMNS[i];
                    n += 1;
                }
                i += 1;
            }
            names
        };

        /// Calls `visitor` for each column, in schema order.
        #[inline(always)]
        pub fn visit<V: $crate::record::Visitor>(visitor: &mut V) {
            $(visitor.column::<$name>();)*
        }

        /// The column types in schema order, as a [`Cons`](crate::record::Cons) list.
        pub type List = columns!(@list $($name)*);

        columns!(@record (t_s, esc, frame, settings) [] []
            $([$(#[doc = $doc])*] $name: $value [$(|$r| $get)?];)*);
    };

    (@list) => { $crate::record::Nil };
    (@list $head:ident $($rest:ident)*) => {
        $crate::record::Cons<$head, columns!(@list $($rest)*)>
    };

    (@cached) => { false };
    (@cached $key:expr) => { true };

    (@get $record:ident, $name:ident) => { $record.$name };
    (@get $record:ident, $name:ident, |$r:pat_param| $get:expr) => {{
        let $r = $record;
        $get
    }};

    (@key $frame:ident) => {{
        let _ = $frame;
        0
    }};
    (@key $frame:ident, |$kf:pat_param| $key:expr) => {{
        let $kf = $frame;
        $key
    }};

    // The record's fields and their values from a frame, gathered entry by entry: a column
    // with a `record` accessor is derived, not a field.
    (@record ($t:ident, $e:ident, $f:ident, $s:ident) [$($field:tt)*] [$($init:tt)*]) => {
        /// One decoded data frame in physical units, as every output presents it: a field per
        /// column of the schema (the `faults` column is derived from `status`).
        #[derive(Debug, Clone, Copy, PartialEq)]
        pub struct Record {
            $($field)*
        }

        impl Record {
            /// Converts a frame received at `t_s` (if the source has timing) from ESC `esc`
            /// under `settings`.
            #[inline]
            pub fn new(
                $t: Option<f64>,
                $e: u8,
                $f: &hwfoc::telemetry::Data,
                $s: &hwfoc::Settings,
            ) -> Record {
                Record {
                    $($init)*
                }
            }
        }
    };
    (@record $args:tt [$($field:tt)*] [$($init:tt)*]
        [$(#[doc = $doc:literal])*] $name:ident: $value:ty [];
        $($rest:tt)*
    ) => {
        columns!(@record $args
            [$($field)* $(#[doc = $doc])* pub $name: $value,]
            [$($init)* $name: columns!(@init $args $name),]
            $($rest)*);
    };
    (@record $args:tt [$($field:tt)*] [$($init:tt)*]
        [$(#[doc = $doc:literal])*] $name:ident: $value:ty [$($derived:tt)+];
        $($rest:tt)*
    ) => {
        columns!(@record $args [$($field)*] [$($init)*] $($rest)*);
    };
    (@init ($t:ident, $e:ident, $f:ident, $s:ident) $name:ident) => {
        <$name as $crate::record::Column>::from_frame($t, $e, $f, $s)
    };
}
