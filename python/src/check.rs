//! `hwfoc.check`: the findings of `hwfoc check` (`hwfoc_io::check`) on a source, as the JSON
//! text of `hwfoc check --json`'s `findings`, which the package's Python side makes an Arrow
//! table of (`hwfoc.check`, columns in docs/CHECKS.md).

use hwfoc::Settings;
use hwfoc_io::InputError;
use hwfoc_io::check::{Baseline, Check, CheckConfig, analyse};
use pyo3::exceptions::PyValueError;
use pyo3::prelude::*;

use crate::source::{self, Spec};
use crate::{
    CURRENT_SCALE, GEAR_RATIO, Notes, POLE_PAIRS, errors, open_all, settings_arg, sources,
    warn_notices,
};

/// The findings on `specs` as JSON, under `config`, drift judged against `baseline`.
fn findings_json(
    specs: Vec<Spec>,
    settings: Settings,
    (config, baseline): (&CheckConfig, Option<&Baseline>),
    notes: &Notes,
) -> Result<Result<String, String>, InputError> {
    let mut sources = sources(open_all(specs, notes)?, settings, (None, false));
    let mut check = Check::new();
    sources.run(&mut check)?;
    if let Some(nothing) = crate::nothing_decoded(&sources) {
        return Ok(Err(nothing));
    }
    let findings = analyse(&check.series(&sources), config, baseline);
    Ok(Ok(serde_json::to_string(&findings).unwrap_or_default()))
}

/// A `ValueError` naming the argument `what` whose JSON does not fit.
fn bad_json(what: &str) -> impl Fn(serde_json::Error) -> PyErr + '_ {
    move |e| PyValueError::new_err(format!("{what}: {e}"))
}

/// The findings of `hwfoc check --json` on `source` (as `read` takes it), as one JSON text
/// (a list of findings); `config` the `[check]` table and `baseline` a fitted baseline, each
/// as JSON text. Raises InputError (also when no input held a data frame, as the command
/// fails), ValueError.
#[pyfunction]
#[pyo3(signature = (source, *, current_scale=CURRENT_SCALE, pole_pairs=crate::args::PolePairs(POLE_PAIRS), gear_ratio=GEAR_RATIO, settings=None, config=None, baseline=None))]
#[allow(clippy::too_many_arguments)]
pub(crate) fn check_json(
    py: Python<'_>,
    source: &Bound<'_, PyAny>,
    current_scale: f32,
    pole_pairs: crate::args::PolePairs,
    gear_ratio: f32,
    settings: Option<crate::FormatSettings<'_>>,
    config: Option<&str>,
    baseline: Option<&str>,
) -> PyResult<String> {
    let settings = settings_arg(current_scale, pole_pairs, gear_ratio, settings)?;
    let config: CheckConfig = match config {
        Some(text) => serde_json::from_str(text).map_err(bad_json("config"))?,
        None => CheckConfig::default(),
    };
    let baseline: Option<Baseline> = baseline
        .map(|text| serde_json::from_str(text).map_err(bad_json("baseline")))
        .transpose()?;
    let specs = source::specs(source)?;
    let notes = Notes::default();
    let json = py.detach(|| findings_json(specs, settings, (&config, baseline.as_ref()), &notes));
    warn_notices(py, &notes)?;
    json.map_err(errors::input)?
        .map_err(errors::InputError::new_err)
}
