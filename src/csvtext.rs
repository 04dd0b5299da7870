//! CSV text: the one writer every table Shoal writes goes through, and the reader of the tables
//! Shoal reads back (the sweep table).
//!
//! Fields are quoted per RFC 4180 only where they must be — a field holding a comma, a double
//! quote or a line break is written in double quotes, its quotes doubled — so a design,
//! instrument, product or study name with a comma stays one field, and a table of plain fields
//! is exactly the comma-joined text it always was (`a,b\n`). Lines end in `\n`.
//!
//! ```
//! use shoal::csvtext::Csv;
//!
//! let mut csv = Csv::new(&["instrument", "mae_pct"]);
//! csv.row(["SmallSat (2x, f/4)", "12.5"]);
//! csv.row(["nominal", "8"]);
//! assert_eq!(csv.finish(), "instrument,mae_pct\n\"SmallSat (2x, f/4)\",12.5\nnominal,8\n");
//! ```

use csv::{QuoteStyle, Terminator, WriterBuilder};

/// A CSV table built in memory: comment lines, a header, then rows.
pub struct Csv {
    /// The comment lines, each with its `\n`: written before the header.
    comments: String,
    /// The header line, with its `\n`.
    header: String,
    /// Columns in the header (every row must have as many fields).
    width: usize,
    /// The rows written so far.
    rows: csv::Writer<Vec<u8>>,
}

fn writer(style: QuoteStyle) -> csv::Writer<Vec<u8>> {
    WriterBuilder::new()
        .quote_style(style)
        .terminator(Terminator::Any(b'\n'))
        // Widths are checked in `Csv::row`; the header is written by another writer.
        .flexible(true)
        .from_writer(Vec::new())
}

/// The bytes a writer holds, as text (every field came in as UTF-8, so nothing is lost).
fn text(mut w: csv::Writer<Vec<u8>>) -> String {
    // Into memory: flushing cannot fail.
    let _ = w.flush();
    String::from_utf8_lossy(w.get_ref()).into_owned()
}

impl Csv {
    /// A table with these column names; fields are quoted only where they must be.
    #[must_use]
    pub fn new(header: &[&str]) -> Self {
        Self::with_rows(header, QuoteStyle::Necessary)
    }

    /// A table whose rows have every field in double quotes (the header is written as by
    /// [`Csv::new`]): the form `reproduction.csv` has always had, its cells being prose.
    #[must_use]
    pub fn quoting_every_field(header: &[&str]) -> Self {
        Self::with_rows(header, QuoteStyle::Always)
    }

    fn with_rows(header: &[&str], style: QuoteStyle) -> Self {
        let mut h = writer(QuoteStyle::Necessary);
        // Into memory: writing cannot fail.
        let _ = h.write_record(header);
        Self { comments: String::new(), header: text(h), width: header.len(), rows: writer(style) }
    }

    /// Add a comment line (`line` should start with `#`), written verbatim before the header
    /// whenever it is added. A line break inside `line` would end the comment early and
    /// corrupt the table, so each becomes a space.
    pub fn comment(&mut self, line: &str) {
        self.comments.extend(line.chars().map(|c| if c == '\n' || c == '\r' { ' ' } else { c }));
        self.comments.push('\n');
    }

    /// Add a row: one field per column of the header, in order.
    pub fn row<S: AsRef<str>>(&mut self, fields: impl IntoIterator<Item = S>) {
        let fields: Vec<S> = fields.into_iter().collect();
        debug_assert_eq!(fields.len(), self.width, "a CSV row as wide as its header");
        // Into memory, rows of any width allowed: writing cannot fail.
        let _ = self.rows.write_record(fields.iter().map(|f| f.as_ref().as_bytes()));
    }

    /// The CSV text: the comment lines, the header, the rows.
    #[must_use]
    pub fn finish(self) -> String {
        let Self { mut comments, header, rows, .. } = self;
        comments.push_str(&header);
        comments.push_str(&text(rows));
        comments
    }
}

/// A record of CSV text: the line it starts on (from 1, comment lines counted) and its fields.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Record {
    /// Line number, from 1.
    pub line: usize,
    /// The fields, unquoted.
    pub fields: Vec<String>,
}

/// Why CSV text could not be read: the line, and what is wrong there (no file name: the caller
/// knows it).
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct ReadError {
    /// Line number, from 1.
    pub line: usize,
    /// What is wrong.
    pub message: String,
}

/// The records of CSV text, in order, the header (if any) being the first: quoted fields may
/// hold commas, doubled quotes and line breaks; lines starting with `#` are comments and
/// skipped, as are empty lines; every record must have as many fields as the first (an error
/// `"5 cells, expected 7"` names the line). Fields are not trimmed.
pub fn records(text: &str) -> impl Iterator<Item = Result<Record, ReadError>> + '_ {
    let reader = csv::ReaderBuilder::new()
        .has_headers(false)
        .comment(Some(b'#'))
        .flexible(false)
        .terminator(Terminator::CRLF)
        .from_reader(text.as_bytes());
    reader.into_records().map(move |r| {
        r.map(|r| Record { line: start_line(text, r.position()), fields: r.iter().map(str::to_string).collect() })
            .map_err(|e| {
                let line = start_line(text, e.position());
                let message = match e.kind() {
                    csv::ErrorKind::UnequalLengths { expected_len, len, .. } => {
                        format!("{len} cells, expected {expected_len}")
                    }
                    _ => e.to_string(),
                };
                ReadError { line, message }
            })
    })
}

/// The line a record starts on. The reader places a record where the one before it ended, so
/// the comment and empty lines it skipped on the way are counted here.
fn start_line(text: &str, position: Option<&csv::Position>) -> usize {
    let Some(p) = position else { return 0 };
    let mut line = usize::try_from(p.line()).unwrap_or(usize::MAX);
    let mut rest = usize::try_from(p.byte()).ok().and_then(|b| text.get(b..)).unwrap_or("");
    while let Some((first, after)) = rest.split_once('\n') {
        if !(first.trim_end_matches('\r').is_empty() || first.starts_with('#')) {
            break;
        }
        line = line.saturating_add(1);
        rest = after;
    }
    line
}

#[cfg(test)]
mod tests {
    #![allow(clippy::unwrap_used)]
    use super::*;

    fn read(text: &str) -> Vec<Record> {
        records(text).collect::<Result<_, _>>().unwrap()
    }

    #[test]
    fn plain_fields_are_the_comma_joined_text() {
        let mut csv = Csv::new(&["a", "b"]);
        assert_eq!(Csv::new(&["a", "b"]).finish(), "a,b\n");
        csv.row(["1.5", ""]);
        csv.row([String::from("x y_z-(1).+"), String::from("2e-5")]);
        assert_eq!(csv.finish(), "a,b\n1.5,\nx y_z-(1).+,2e-5\n");
    }

    #[test]
    fn a_name_with_a_comma_and_a_quote_round_trips() {
        let name = "SmallSat (2x, f/4) \"my\" algo";
        let mut csv = Csv::new(&["name", "note, with comma", "n"]);
        csv.comment("# sweep a, b | jobs 2");
        csv.row([name, "two\nlines", "3"]);
        let text = csv.finish();
        assert_eq!(
            text,
            "# sweep a, b | jobs 2\nname,\"note, with comma\",n\n\"SmallSat (2x, f/4) \"\"my\"\" algo\",\"two\nlines\",3\n"
        );
        let r = read(&text);
        assert_eq!(r.len(), 2);
        assert_eq!((r[0].line, r[0].fields.clone()), (2, vec!["name".into(), "note, with comma".into(), "n".into()]));
        assert_eq!((r[1].line, r[1].fields.clone()), (3, vec![name.into(), "two\nlines".into(), "3".into()]));
    }

    #[test]
    fn every_field_quoted_keeps_a_plain_header() {
        let mut csv = Csv::quoting_every_field(&["q", "note"]);
        csv.row(["a", "say \"hi\", twice"]);
        assert_eq!(csv.finish(), "q,note\n\"a\",\"say \"\"hi\"\", twice\"\n");
    }

    #[test]
    fn comments_stay_one_line_and_come_first() {
        let mut csv = Csv::new(&["a", "b"]);
        csv.row(["1", "2"]);
        csv.comment("# one\ntwo");
        assert_eq!(csv.finish(), "# one two\na,b\n1,2\n");
    }

    #[test]
    fn a_ragged_record_is_refused_naming_its_line() {
        let e = records("# c\na,b,c\n1,2,3\n\n4,5\n").collect::<Result<Vec<_>, _>>().unwrap_err();
        assert_eq!(e, ReadError { line: 5, message: "2 cells, expected 3".into() });
        assert_eq!(read("a,b\r\n1,2\r\n")[1].fields, ["1", "2"]);
    }
}
