//! The image file of a plot: its format from its name, opened before any input is read so that
//! a wrong name or an unwritable place is reported at once, not after minutes of decoding.

use std::fs::{self, File};
use std::io::{self, Write};
use std::path::{Path, PathBuf};

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

/// The image file: written under its partial name (`FILE.partial`, made when the target is
/// opened, so that an unwritable place is reported at once) and renamed into place once the
/// image is complete. An existing file stays as it was until then; the partial file is removed
/// if nothing is written.
#[derive(Debug)]
pub struct Target {
    path: String,
    format: ImageFormat,
    /// The file replaced: the path, or the file a link at the path points to.
    target: PathBuf,
    partial: PathBuf,
    file: Option<File>,
}

impl Target {
    /// Checks the name's format, refuses anything but a (new or) regular file, and creates the
    /// partial file.
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
        // Through a link, the file it points to is replaced, not the link.
        let target = fs::canonicalize(path).unwrap_or_else(|_| PathBuf::from(path));
        let mut partial = target.clone().into_os_string();
        partial.push(hwfoc_io::write::PARTIAL_SUFFIX);
        let partial = PathBuf::from(partial);
        let file = File::create(&partial).map_err(create)?;
        Ok(Target {
            path: path.to_string(),
            format,
            target,
            partial,
            file: Some(file),
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

    /// Writes `bytes` as the file's content: to the partial file, then renamed into place.
    pub fn write(&mut self, bytes: &[u8]) -> Result<(), CliError> {
        let error = |source| WriteError::Write {
            output: self.path.clone(),
            source,
        };
        let Some(mut file) = self.file.take() else {
            return Err(error(io::Error::other("the image was written already")).into());
        };
        file.write_all(bytes)
            .and_then(|()| file.flush())
            .map_err(error)?;
        drop(file);
        fs::rename(&self.partial, &self.target).map_err(error)?;
        Ok(())
    }
}

impl Drop for Target {
    /// Removes the partial file if the image was not written.
    fn drop(&mut self) {
        if self.file.is_some() {
            let _ = fs::remove_file(&self.partial);
        }
    }
}
