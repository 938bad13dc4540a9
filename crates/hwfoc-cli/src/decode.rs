//! `hwfoc decode`: one record per data frame, as JSON Lines or CSV.

use hwfoc::Frame;

use crate::error::CliError;
use crate::input::Input;
use crate::output::Output;
use crate::schema::Record;
use crate::stream::Stream;
use crate::{DecodeArgs, RecordFormat};

/// Output is handed to the sink once this much text has built up (and after every input batch).
const FLUSH_AT: usize = 1 << 20;

pub fn run(args: &DecodeArgs) -> Result<(), CliError> {
    let settings = args.settings.settings()?;
    let mut input = args.input.open()?;
    let mut out = Output::create(args.output.as_deref())?;
    let mut text = Vec::with_capacity(2 * FLUSH_AT);
    if args.format == RecordFormat::Csv {
        if args.settings_comment {
            text.extend_from_slice(
                format!(
                    "# hwfoc decode: current_scale={} pole_pairs={} gear_ratio={} input={}\n",
                    settings.current_scale,
                    settings.pole_pairs,
                    settings.gear_ratio,
                    input.name()
                )
                .as_bytes(),
            );
        }
        Record::write_csv_header(&mut text);
    }
    let mut stream = Stream::new();
    let mut emit = |t_s: Option<f64>, d: hwfoc::Decoded, text: &mut Vec<u8>| {
        if let Frame::Data(frame) = d.frame {
            let record = Record::new(t_s, 0, &frame, &settings);
            match args.format {
                RecordFormat::Jsonl => record.write_json(text),
                RecordFormat::Csv => record.write_csv(text),
            }
        }
    };
    let result = decode_all(&mut input, &mut stream, &mut out, &mut text, &mut emit);
    // Whatever was decoded before an input error is still written out.
    let written = out.write(&mut text).and_then(|()| out.flush());
    result?;
    written?;
    if stream.stats().frames() == 0 {
        eprintln!(
            "hwfoc: warning: {}: {}",
            input.name(),
            crate::summary::NO_FRAMES
        );
    }
    Ok(())
}

fn decode_all(
    input: &mut Input,
    stream: &mut Stream,
    out: &mut Output,
    text: &mut Vec<u8>,
    emit: &mut impl FnMut(Option<f64>, hwfoc::Decoded, &mut Vec<u8>),
) -> Result<(), CliError> {
    let result = loop {
        let batch = match input.next_batch() {
            Ok(Some(batch)) => batch,
            Ok(None) => break Ok(()),
            Err(e) => break Err(e),
        };
        stream.feed(batch, |t, d| emit(t, d, text));
        // Small batches come from a live stream: pass them on at once.
        if text.len() >= FLUSH_AT || batch.bytes.len() < 4096 {
            out.write(text)?;
            out.flush()?;
        }
    };
    // Even after an input error, frames already received are decoded.
    stream.finish(|t, d| emit(t, d, text));
    result
}
