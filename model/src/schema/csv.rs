//! Tables of points in a CSV file: two numeric columns (three for a surface's grid), one point
//! per line.
//!
//! The format is the plain one CAD programs and spreadsheets export: cells separated by a
//! comma (or a semicolon or a tab), spaces around them ignored, blank lines and lines whose
//! first character is `#` skipped, and an optional header line naming the two columns. A
//! table has no quoting or other cell types, so it is read here in a few lines that locate
//! every problem by line and column rather than through a general CSV library.

/// One point of a table (of N columns) and where it is written.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct Row<const N: usize = 2> {
    /// The numbers.
    pub values: [f64; N],
    /// 1-based line.
    pub line: usize,
    /// 1-based column of each cell.
    pub columns: [usize; N],
}

/// A problem in a table file, at a 1-based line and column.
#[derive(Debug, Clone, PartialEq, Eq)]
pub(crate) struct CsvError {
    pub line: usize,
    pub column: usize,
    pub message: String,
}

/// The rows of `text`, whose header, if it has one, must name the columns `names` (in any
/// letter case).
pub(crate) fn read<const N: usize>(text: &str, names: [&str; N]) -> Result<Vec<Row<N>>, CsvError> {
    let mut rows = Vec::new();
    let mut seen_data_or_header = false;
    for (index, line) in text.lines().enumerate() {
        let number = index + 1;
        let content = line.trim_start_matches('\u{feff}');
        if content.trim().is_empty() || content.trim_start().starts_with('#') {
            continue;
        }
        let cells = split(content);
        let first_is_text = cells
            .first()
            .is_some_and(|(_, cell)| cell.parse::<f64>().is_err());
        if !seen_data_or_header && first_is_text {
            seen_data_or_header = true;
            header(&cells, &names, number)?;
            continue;
        }
        seen_data_or_header = true;
        if cells.len() != N {
            return Err(CsvError {
                line: number,
                column: cells.first().map_or(1, |(c, _)| *c),
                message: format!(
                    "a row holds {} numbers ({}), this one has {} cell{}",
                    count(N),
                    names.join(", "),
                    cells.len(),
                    if cells.len() == 1 { "" } else { "s" }
                ),
            });
        }
        let mut values = [0.0; N];
        let mut columns = [0; N];
        for (k, (column, cell)) in cells.iter().enumerate() {
            values[k] = number_in(cell, names[k], N, (number, *column))?;
            columns[k] = *column;
        }
        rows.push(Row {
            values,
            line: number,
            columns,
        });
    }
    Ok(rows)
}

/// The cells of a line with their 1-based columns, split at commas, semicolons or tabs (or
/// at runs of spaces when the line has none of them), trimmed and unquoted.
fn split(line: &str) -> Vec<(usize, &str)> {
    let separators: &[char] = if line.contains([',', ';', '\t']) {
        &[',', ';', '\t']
    } else {
        &[' ']
    };
    let mut cells = Vec::new();
    let mut start = 0;
    for piece in line.split(separators) {
        let trimmed = piece.trim();
        let offset = start + (piece.len() - piece.trim_start().len());
        start += piece.len() + 1;
        if separators == [' '] && trimmed.is_empty() {
            continue;
        }
        let unquoted = trimmed
            .strip_prefix('"')
            .and_then(|t| t.strip_suffix('"'))
            .unwrap_or(trimmed);
        let column = line[..offset.min(line.len())].chars().count() + 1;
        cells.push((column, unquoted));
    }
    cells
}

/// The header must name the columns as expected.
fn header(cells: &[(usize, &str)], names: &[&str], line: usize) -> Result<(), CsvError> {
    let given: Vec<String> = cells.iter().map(|(_, c)| c.to_ascii_lowercase()).collect();
    if given.len() == names.len() && given.iter().zip(names).all(|(g, n)| g == n) {
        return Ok(());
    }
    Err(CsvError {
        line,
        column: cells.first().map_or(0, |(c, _)| *c),
        message: format!(
            "the header names the columns `{}`, but this table's columns are `{}` (or write no \
             header)",
            cells.iter().map(|(_, c)| *c).collect::<Vec<_>>().join(", "),
            names.join(", ")
        ),
    })
}

/// "two" or "three": how many numbers a row holds.
fn count(n: usize) -> String {
    match n {
        2 => "two".to_string(),
        3 => "three".to_string(),
        _ => n.to_string(),
    }
}

/// A cell's finite number (of a row of `n`).
fn number_in(
    cell: &str,
    name: &str,
    n: usize,
    (line, column): (usize, usize),
) -> Result<f64, CsvError> {
    let message = match cell.parse::<f64>() {
        Ok(v) if v.is_finite() => return Ok(v),
        Ok(_) => format!("{name} must be a finite number, not `{cell}`"),
        Err(_) if cell.is_empty() => {
            format!("the {name} cell is empty: a row holds {} numbers", count(n))
        }
        Err(_) => format!("`{cell}` is not a number ({name})"),
    };
    Err(CsvError {
        line,
        column,
        message,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn reads_points_with_a_header_comments_and_separators() {
        let text = "# a cam\ntheta, r\n0, 0.03\n\n0.5;0.031\n1.0\t0.032\n  2.0   0.035  \n";
        let rows = read(text, ["theta", "r"]).expect("a valid table");
        let values: Vec<[f64; 2]> = rows.iter().map(|r| r.values).collect();
        assert_eq!(
            values,
            vec![[0.0, 0.03], [0.5, 0.031], [1.0, 0.032], [2.0, 0.035]]
        );
        assert_eq!(
            rows.iter().map(|r| r.line).collect::<Vec<_>>(),
            vec![3, 5, 6, 7]
        );
        assert_eq!(rows[0].columns, [1, 4]);
        assert_eq!(rows[3].columns, [3, 9]);
    }

    #[test]
    fn locates_bad_cells_rows_and_headers() {
        let bad = read("x,y\n0,1\n0.5,abc\n", ["x", "y"]).unwrap_err();
        assert_eq!((bad.line, bad.column), (3, 5));
        assert!(bad.message.contains("`abc` is not a number (y)"), "{bad:?}");
        let short = read("0,1\n2\n", ["x", "y"]).unwrap_err();
        assert_eq!(short.line, 2);
        assert!(short.message.contains("has 1 cell"), "{short:?}");
        let header = read("x,y\n0,1\n", ["theta", "r"]).unwrap_err();
        assert_eq!((header.line, header.column), (1, 1));
        assert!(header.message.contains("`theta, r`"), "{header:?}");
        let infinite = read("0,inf\n", ["x", "y"]).unwrap_err();
        assert!(infinite.message.contains("finite"), "{infinite:?}");
        // A word after the first data line is an error, not a second header.
        let late = read("0,1\nx,y\n", ["x", "y"]).unwrap_err();
        assert_eq!(late.line, 2);
    }
}
