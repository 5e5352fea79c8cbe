//! What the tables of points share (`table:` profiles, [`super::tables`], and surfaces through
//! grids, [`super::grids`]): reading a table's file beside the model, the bound on its numbers
//! and its ends as the runtime names them.

use super::{Checked, Context};
use crate::model::ModelFile;
use crate::schema::raw::TableEnds;
use crate::schema::{Files, read_text};
use camchain_runtime::spline::Ends;
use std::path::{Path, PathBuf};

/// Most points a table (or a surface's grid) holds: the generated code keeps them and the
/// spline's derivatives at them as constants (three or four numbers a point), which the Rust
/// compiler takes about 10 s and 1 GB per million to build; 250 000 points (a 500 × 500 grid)
/// stay within a few seconds, far beyond what a cam needs (a 0.1° polar table has 3601).
pub(crate) const MAX_TABLE_POINTS: usize = 250_000;

/// The error of a table of `count` points beyond [`MAX_TABLE_POINTS`].
pub(super) fn too_many_points(count: usize) -> String {
    format!(
        "the table has {count} points, more than the {MAX_TABLE_POINTS} a table may hold (the \
         generated code keeps every point as a constant): sample it more coarsely"
    )
}

/// Largest magnitude of a number in a table. The spline's arithmetic squares and cubes
/// differences of the table's numbers and sums up to a table's length of them (chord
/// lengths, slopes, the cubic's terms): below 1e100 every such product stays below 1e300,
/// far inside f64's 1.8e308, while any physical table (metres, radians, degrees) is many
/// orders of magnitude below it.
pub(crate) const LARGEST: f64 = 1e100;

/// The spline's ends as the runtime names them.
pub(super) fn ends_of(ends: TableEnds) -> Ends {
    match ends {
        TableEnds::Natural => Ends::Natural,
        TableEnds::Clamped { start, end } => Ends::Clamped { start, end },
        TableEnds::Periodic => Ends::Periodic,
    }
}

/// The text of the file the model names `written`, and the path its messages show (beside
/// the model file's); recorded among the files the model read.
pub(super) fn read_file(cx: &Context, field: &str, written: &str) -> Checked<(String, PathBuf)> {
    let beside = cx.at.file.parent().unwrap_or(Path::new(""));
    let shown = beside.join(written);
    let (text, path) = match cx.files {
        Files::BesideModel => (read_text(&shown), shown.clone()),
        Files::In(dir) => {
            let path = dir.join(written);
            (read_text(&path), path)
        }
        Files::Embedded(list) => match list.iter().find(|(name, _)| *name == written) {
            Some((_, text)) => (Ok((*text).to_string()), PathBuf::new()),
            None => (
                Err(std::io::Error::new(
                    std::io::ErrorKind::NotFound,
                    "not among the files embedded with the model",
                )),
                PathBuf::new(),
            ),
        },
    };
    let text = text.map_err(|e| {
        cx.at.error(
            field,
            format!(
                "cannot read the table file `{written}` ({}): {e}",
                shown.display()
            ),
        )
    })?;
    cx.read.borrow_mut().push(ModelFile {
        written: written.to_string(),
        path,
        text: text.clone(),
    });
    Ok((text, shown))
}
