//! A recording held in memory, read as the command reads a file: its format told from its
//! content, its streams numbered into ESCs, every frame a record, the summary of `hwfoc summary
//! --json`, and the notices the command prints on its standard error.

use std::io::{self, Cursor, Read};
use std::sync::{Arc, Mutex};

use hwfoc::Settings;
use hwfoc_records::summary::{self, Summary};
use hwfoc_records::{BlockRead, ReadAt, RegularFile, Reopen};
use hwfoc_records::{Both, Handler, Input, InputError, Record, Sources};

use crate::columns::Columns;

/// What a recording gave.
pub struct Opened {
    /// Its records, column by column.
    pub columns: Columns,
    /// `hwfoc summary --json`'s object, as JSON text.
    pub summary: String,
    /// The notices, as the command's standard error lines.
    pub notices: Vec<String>,
}

/// A file held in memory, opened again from its start as the command opens a file by its path
/// (a CAN bus's ESC numbers are planned on a first reading of the whole file).
struct Memory {
    name: String,
    bytes: Arc<[u8]>,
}

/// One reading of a [`Memory`] file.
struct MemoryFile(Cursor<Arc<[u8]>>);

impl Read for MemoryFile {
    fn read(&mut self, buf: &mut [u8]) -> io::Result<usize> {
        self.0.read(buf)
    }
}

impl RegularFile for MemoryFile {
    fn read_ahead(self: Box<Self>) -> Result<Box<dyn BlockRead>, Box<dyn RegularFile>> {
        Err(self)
    }

    fn second(&self) -> Option<Box<dyn ReadAt>> {
        None
    }
}

impl Reopen for Memory {
    fn open(&self) -> io::Result<Box<dyn RegularFile>> {
        Ok(Box::new(MemoryFile(Cursor::new(Arc::clone(&self.bytes)))))
    }

    fn file_len(&self) -> Option<u64> {
        Some(self.bytes.len() as u64)
    }

    /// One file is read at a time here: never another's copy.
    fn same_bytes_as(&self, _: &dyn Reopen) -> bool {
        false
    }

    fn path(&self) -> &str {
        &self.name
    }
}

/// The records of a recording, gathered column by column.
struct Collect<'a>(&'a mut Columns);

impl Handler for Collect<'_> {
    type Error = InputError;

    fn record(&mut self, record: &Record) {
        self.0.push_record(record);
    }
}

/// Reads the recording `bytes`, named `name` in notices and the summary.
pub fn open(name: &str, bytes: Vec<u8>) -> Opened {
    let notices = Arc::new(Mutex::new(Vec::new()));
    let mut columns = Columns::default();
    let memory = Memory {
        name: name.to_owned(),
        bytes: bytes.into(),
    };
    let file = match memory.open() {
        Ok(file) => file,
        Err(e) => {
            return Opened {
                columns,
                summary: "null".to_owned(),
                notices: vec![format!("hwfoc: {name}: {e}")],
            };
        }
    };
    let mut input = match Input::from_file(name, Box::new(memory), file) {
        Ok(input) => input,
        Err(e) => {
            return Opened {
                columns,
                summary: "null".to_owned(),
                notices: vec![format!("hwfoc: {e}")],
            };
        }
    };
    let sink = Arc::clone(&notices);
    input.set_notices(move |n| sink.lock().map(|mut v| v.push(n.line())).unwrap_or(()));
    let mut sources = Sources::new(vec![input], Settings::DEFAULT);
    let mut summary = Summary::new();
    let result = sources.run(&mut Both(&mut summary, &mut Collect(&mut columns)));
    let mut notices = notices.lock().map(|v| v.clone()).unwrap_or_default();
    notices.extend(summary::left_out(&sources).iter().map(|n| n.line()));
    if let Err(e) = result {
        notices.push(format!("hwfoc: {e}"));
    }
    let summary = summary.report(&sources).json().to_string();
    Opened {
        columns,
        summary,
        notices,
    }
}
