//! The image file of a plot: its format from its name, opened before any input is read so that
//! a wrong name or an unwritable place is reported at once, not after minutes of decoding.

use std::fs::{self, File};
use std::io::{self, Write};
use std::path::Path;

use crate::error::CliError;
use hwfoc_io::write::{Staging, WriteError};

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

/// The image file: written under a temporary name (a [`Staging`], made when the target is
/// opened, so that an unwritable place is reported at once) and renamed into place once the
/// image is complete. An existing file stays as it was until then; the temporary file is
/// removed if nothing is written.
#[derive(Debug)]
pub struct ImageFile {
    path: String,
    format: ImageFormat,
    /// The temporary file, until the image is written.
    staging: Option<(Staging, File)>,
}

impl ImageFile {
    /// Checks the name's format, refuses anything but a (new or) regular file, and an existing
    /// one unless `overwrite`, and creates the temporary file.
    pub fn open(path: &str, overwrite: bool) -> Result<ImageFile, CliError> {
        let format = ImageFormat::from_name(path).ok_or_else(|| CliError::Usage {
            option: format!("-o {path}"),
            message: "the image format follows the file name: use a name ending in .png or .svg"
                .to_string(),
        })?;
        let create = |source| WriteError::Create {
            output: path.to_string(),
            source,
        };
        match fs::metadata(path) {
            Ok(m) if m.is_dir() => return Err(create(io::ErrorKind::IsADirectory.into()).into()),
            Ok(m) if !m.is_file() => {
                return Err(CliError::Usage {
                    option: format!("-o {path}"),
                    message: "it is a device or a pipe, not a file: a plot is written to a \
                              .png or .svg file"
                        .to_string(),
                });
            }
            _ => {}
        }
        let exists = |source: io::Error| match source.kind() {
            io::ErrorKind::AlreadyExists => WriteError::Exists {
                output: path.to_string(),
            },
            _ => create(source),
        };
        let (staging, file) = Staging::create_new(Path::new(path), overwrite).map_err(exists)?;
        Ok(ImageFile {
            path: path.to_string(),
            format,
            staging: Some((staging, file)),
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

    /// Writes `bytes` as the file's content: to the temporary file, then renamed into place.
    pub fn write(&mut self, bytes: &[u8]) -> Result<(), CliError> {
        let error = |source| WriteError::Write {
            output: self.path.clone(),
            source,
        };
        let Some((staging, mut file)) = self.staging.take() else {
            return Err(error(io::Error::other("the image was written already")).into());
        };
        file.write_all(bytes)
            .and_then(|()| file.flush())
            .map_err(error)?;
        drop(file);
        staging.commit().map_err(|source| match source.kind() {
            io::ErrorKind::AlreadyExists => WriteError::Exists {
                output: self.path.clone(),
            },
            _ => error(source),
        })?;
        Ok(())
    }
}
