//! The end of an input read ahead by windows (a recording, a CAN log): reached at the end of
//! the file or at a read error, which is handed out once, after the batches read before it.

use super::InputError;

/// Whether a reader has read its input to the end, and the read error that ended it, until
/// [`End::result`] hands it out.
#[derive(Debug, Default)]
pub(super) struct End {
    reached: bool,
    error: Option<InputError>,
}

impl End {
    /// The input is read to its end.
    pub(super) fn reach(&mut self) {
        self.reached = true;
    }

    /// The input ended at read error `error`.
    pub(super) fn fail(&mut self, error: InputError) {
        self.error = Some(error);
        self.reached = true;
    }

    /// `fill`'s result at the end: the read error that ended the input (once), then 0 (no
    /// stream: no more bytes); `None` while there is more to read.
    pub(super) fn result(&mut self) -> Option<Result<usize, InputError>> {
        self.reached.then(|| self.error.take().map_or(Ok(0), Err))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Nothing before the end; at a read error, the error once, then 0 for ever after.
    #[test]
    fn the_error_is_handed_out_once_then_the_end() {
        let mut end = End::default();
        assert!(end.result().is_none());
        end.fail(InputError::Empty {
            input: "x.log".to_string(),
        });
        assert!(matches!(end.result(), Some(Err(InputError::Empty { .. }))));
        assert!(matches!(end.result(), Some(Ok(0))));
        let mut end = End::default();
        end.reach();
        assert!(matches!(end.result(), Some(Ok(0))));
    }
}
