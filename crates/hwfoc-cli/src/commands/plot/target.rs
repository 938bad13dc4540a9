//! The image file of a plot: its format from its name, opened before any input is read so that
//! a wrong name or an unwritable place is reported at once, not after minutes of decoding.

use std::fs::{self, File, OpenOptions};
use std::io::{self, Write};
use std::path::Path;

use crate::error::CliError;
use hwfoc_io::write::WriteError;

/// What the image is written as.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum ImageFormat {
    /// PNG, 8-bit RGB.
    Png,
    /// SVG: text stays text.
    Svg,
}

impl ImageFormat {
    /// The format a file name asks for: `.png` or `.svg`, in any case.
    pub fn from_name(name: &str) -> Option<ImageFormat> {
        let ext = Path::new(name).extension()?.to_str()?;
        if ext.eq_ignore_ascii_case("png") {
            Some(ImageFormat::Png)
        } else if ext.eq_ignore_ascii_case("svg") {
            Some(ImageFormat::Svg)
        } else {
            None
        }
    }
}

/// The image file, open for writing but not yet truncated: an existing file stays as it was
/// until the image is ready, and a file this command created is removed if nothing is written.
#[derive(Debug)]
pub struct Target {
    path: String,
    format: ImageFormat,
    file: File,
    created: bool,
    written: bool,
}

impl Target {
    /// Checks the name's format and opens (or creates) the file.
    pub fn open(path: &str) -> Result<Target, CliError> {
        let format = ImageFormat::from_name(path).ok_or_else(|| CliError::Usage {
            option: format!("-o {path}"),
            message: "the image format follows the file name: use a name ending in .png or .svg"
                .to_string(),
        })?;
        let create = |source| WriteError::Create {
            output: path.to_string(),
            source,
        };
        let (file, created) = match OpenOptions::new().write(true).create_new(true).open(path) {
            Ok(file) => (file, true),
            Err(e) if e.kind() == io::ErrorKind::AlreadyExists => (
                OpenOptions::new().write(true).open(path).map_err(create)?,
                false,
            ),
            Err(e) => return Err(create(e).into()),
        };
        Ok(Target {
            path: path.to_string(),
            format,
            file,
            created,
            written: false,
        })
    }

    /// The file's name as given.
    pub fn name(&self) -> &str {
        &self.path
    }

    /// The format its name asks for.
    pub fn format(&self) -> ImageFormat {
        self.format
    }

    /// Replaces the file's content with `bytes`.
    pub fn write(&mut self, bytes: &[u8]) -> Result<(), CliError> {
        let result = self
            .file
            .set_len(0)
            .and_then(|()| self.file.write_all(bytes))
            .and_then(|()| self.file.flush());
        result.map_err(|source| WriteError::Write {
            output: self.path.clone(),
            source,
        })?;
        self.written = true;
        Ok(())
    }
}

impl Drop for Target {
    /// Removes the file if this command created it and wrote nothing to it.
    fn drop(&mut self) {
        if self.created && !self.written {
            let _ = fs::remove_file(&self.path);
        }
    }
}
