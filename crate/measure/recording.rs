//! Reading a recording: CSV text with a time column and one or more signal columns.
//!
//! - Klipper's raw accelerometer files (`ACCELEROMETER_MEASURE`, `TEST_RESONANCES` with raw
//!   output) are read as they are: a header `#time,accel_x,accel_y,accel_z`, then one row per
//!   sample, times in seconds.
//! - RepRapFirmware's accelerometer files (`M956`, `0:/sys/accelerometer/*.csv`): a header
//!   `Sample,X,Y,Z` (the axes recorded), one row per sample numbered from 0 with the
//!   accelerations in g, and a last line `Rate <Hz>, overflows <n>` (RepRapFirmware
//!   src/Accelerometers/Accelerometers.cpp, `AccelerometerTaskCode` and `CreateFile`). The
//!   times are the sample numbers over that rate; the values are turned into mm/s² (× 9806.65,
//!   Klipper's unit) in channels `accel_x`, `accel_y`, `accel_z`. A file with overflows (samples
//!   lost), no rate line (unless `timeScale` gives the sample period) or a firmware message in
//!   place of data is refused with the line and the reason.
//! - Any other CSV: the first line that is not a `#` comment names the columns (a leading `#`
//!   is allowed, as in Klipper's files); one column is the time — named `time`, `t`,
//!   `timestamp`, `time_s`, `seconds` … (case-insensitive; or any name given as
//!   `timeColumn`) — and every other column is a signal. Separators: comma, semicolon, tab or
//!   blanks (guessed from the header). Blank lines and later `#` lines are skipped.
//!
//! Times must increase strictly. When they are not evenly spaced (a step differs from the mean
//! by more than 0.1 % of it and more than 1.01 µs — the rounding of Klipper's 6-decimal times —
//! as with accelerometers read in batches) the signals are resampled onto an even
//! grid t₀ + k/f_s, f_s = (n − 1)/(t_last − t₀), by cubic Hermite interpolation (slopes of the
//! parabola through three neighbours); the
//! sample rate and the timing statistics are reported either way.
//!
//! Text can be fed in chunks ([`RecordingParser::push`]), so a page can read a large file
//! piece by piece and show progress. Every error names the line (1-based) and, where it
//! applies, the column (1-based, with its header name).

use super::spectrum_file::{
    axis_from_file_name, resolution, FittedShaper, Normalization, SpectrumChannel, SpectrumFile,
};
use crate::error::Error;
use serde::{Deserialize, Serialize};
use std::fmt;

/// Most data rows accepted (10⁷; a 10⁶-row Klipper file is ~35 MB).
pub const MAX_ROWS: usize = 10_000_000;
/// Most columns accepted.
pub const MAX_COLUMNS: usize = 64;
/// Longest line accepted, in bytes.
pub const MAX_LINE_BYTES: usize = 65_536;

/// Names recognised as the time column (compared case-insensitively, after trimming).
pub const TIME_NAMES: &[&str] = &[
    "time",
    "t",
    "times",
    "timestamp",
    "time_s",
    "time[s]",
    "time (s)",
    "time(s)",
    "seconds",
    "sec",
    "s",
];

/// Options of the parser (JS: `{ timeColumn, timeScale, fileName, channel }`).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(rename_all = "camelCase", default)]
pub struct RecordingOptions {
    /// Name of the time column, when it is not one of [`TIME_NAMES`].
    pub time_column: Option<String>,
    /// Factor turning the time column into seconds (default 1; 0.001 for milliseconds).
    pub time_scale: f64,
    /// The file's name: errors name it, and a Klipper spectrum's axis is read from it.
    pub file_name: Option<String>,
    /// For spectrum files, the channel `psd` holds (default `sum`, Klipper's `psd_xyz`).
    pub channel: SpectrumChannel,
}

impl Default for RecordingOptions {
    fn default() -> Self {
        RecordingOptions {
            time_column: None,
            time_scale: 1.0,
            file_name: None,
            channel: SpectrumChannel::Sum,
        }
    }
}

/// Which kind of file it was.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
#[serde(rename_all = "camelCase")]
pub enum RecordingFormat {
    /// Klipper's raw accelerometer CSV (`#time,accel_x,accel_y,accel_z`).
    Klipper,
    /// Any other CSV with a time column.
    Csv,
    /// Klipper's `resonances_<axis>_<name>.csv` (`freq,psd_x,psd_y,psd_z,psd_xyz`).
    KlipperResonances,
    /// Klipper's `calibration_data_<axis>_<name>.csv` (the PSDs, then `shapers:` and one
    /// column per fitted shaper).
    KlipperCalibration,
    /// RepRapFirmware's accelerometer file (`M956`: `Sample,X,Y,Z`, values in g, then
    /// `Rate <Hz>, overflows <n>`), read into mm/s².
    Rrf,
}

/// Standard gravity, mm/s² per g: RepRapFirmware writes accelerations in g.
pub const G_MM_S2: f64 = 9806.65;

/// A RepRapFirmware accelerometer header (`Sample` then 1–3 distinct axes of `X`, `Y`, `Z`):
/// the channels' names in Klipper's terms.
fn rrf_channels(names: &[String]) -> Option<Vec<String>> {
    if names.first().map(String::as_str) != Some("Sample") || !(2..=4).contains(&names.len()) {
        return None;
    }
    let axes = &names[1..];
    let known = axes.iter().all(|a| matches!(a.as_str(), "X" | "Y" | "Z"));
    let distinct = (0..axes.len()).all(|i| !axes[..i].contains(&axes[i]));
    (known && distinct).then(|| {
        axes.iter()
            .map(|a| format!("accel_{}", a.to_ascii_lowercase()))
            .collect()
    })
}

/// What a RepRapFirmware file's last line says: its sample rate (Hz) and how many times the
/// accelerometer's buffer overflowed (`Rate 1344, overflows 0`).
fn rrf_trailer(text: &str) -> Option<(f64, u64)> {
    let rest = text.strip_prefix("Rate ")?;
    let (rate, overflows) = rest.split_once(',')?;
    let overflows = overflows.trim().strip_prefix("overflows")?.trim();
    Some((rate.trim().parse().ok()?, overflows.parse().ok()?))
}

/// One signal column.
#[derive(Debug, Clone, PartialEq, Serialize)]
#[serde(rename_all = "camelCase")]
pub struct Channel {
    /// The header name.
    pub name: String,
    /// Samples on the even grid (resampled if the file's times were uneven).
    pub values: Vec<f64>,
}

/// How the file's time stamps were spaced.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
#[serde(rename_all = "camelCase")]
pub struct Timing {
    /// Mean step (t_last − t₀)/(n − 1), s.
    pub mean_step_s: f64,
    /// Smallest step, s.
    pub min_step_s: f64,
    /// Largest step, s (a gap in the recording shows here).
    pub max_step_s: f64,
    /// Standard deviation of the steps divided by the mean step.
    pub jitter: f64,
}

/// A parsed recording on an even time grid.
#[derive(Debug, Clone, PartialEq, Serialize)]
#[serde(rename_all = "camelCase")]
pub struct Recording {
    /// Klipper or generic CSV.
    pub format: RecordingFormat,
    /// Name of the time column.
    pub time_column: String,
    /// The signal columns, in file order.
    pub channels: Vec<Channel>,
    /// Sample rate of the even grid, Hz.
    pub sample_rate_hz: f64,
    /// Time of the first sample, s.
    pub start_time_s: f64,
    /// t_last − t₀, s.
    pub duration_s: f64,
    /// Number of samples (data rows).
    pub rows: usize,
    /// Whether the signals were resampled because the times were uneven.
    pub resampled: bool,
    /// Spacing statistics of the file's time stamps.
    pub timing: Timing,
    /// The time of each sample, s: the file's own when they were even, else the grid
    /// t₀ + k/f_s. Not serialised (the JS API returns the channels only).
    #[serde(skip)]
    pub time_s: Vec<f64>,
}

impl Recording {
    /// The channel called `name`.
    pub fn channel(&self, name: &str) -> Option<&Channel> {
        self.channels.iter().find(|c| c.name == name)
    }

    /// The time of each sample, s (see [`Recording::time_s`]).
    pub fn time(&self) -> &[f64] {
        &self.time_s
    }
}

/// A parse error at a place in the file.
#[derive(Debug, Clone, PartialEq)]
pub struct RecordingError {
    /// 1-based line number (0 when the error concerns the file as a whole).
    pub line: usize,
    /// 1-based column number, when the error concerns one field.
    pub column: Option<usize>,
    /// The column's header name, when known.
    pub column_name: Option<String>,
    /// What is wrong, in words.
    pub reason: String,
    /// Too-large errors (rows, columns, line length) are reported as [`Error::TooLarge`].
    pub too_large: Option<(f64, f64)>,
    /// The file's name, when the options gave it.
    pub file: Option<String>,
}

impl RecordingError {
    fn at(line: usize, reason: impl Into<String>) -> Self {
        RecordingError {
            line,
            column: None,
            column_name: None,
            reason: reason.into(),
            too_large: None,
            file: None,
        }
    }
    fn field(line: usize, column: usize, name: &str, reason: impl Into<String>) -> Self {
        RecordingError {
            line,
            column: Some(column),
            column_name: Some(name.to_string()),
            reason: reason.into(),
            too_large: None,
            file: None,
        }
    }
    /// "`resonances_x.csv`, line 12, column 3 (`psd_y`)" — where the error is.
    pub fn location(&self) -> String {
        let mut s = match &self.file {
            Some(f) => format!("`{f}`, "),
            None => String::new(),
        };
        if self.line > 0 {
            s.push_str(&format!("line {}", self.line));
        } else if self.file.is_some() {
            s.pop();
            s.pop();
        } else {
            s.push_str("recording");
        }
        if let Some(c) = self.column {
            s.push_str(&format!(", column {c}"));
            if let Some(n) = &self.column_name {
                s.push_str(&format!(" (`{n}`)"));
            }
        }
        s
    }
}

impl fmt::Display for RecordingError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "{}: {}", self.location(), self.reason)
    }
}

impl From<RecordingError> for Error {
    fn from(e: RecordingError) -> Error {
        match e.too_large {
            Some((value, limit)) => Error::TooLarge {
                field: format!("recording ({})", e.location()),
                value,
                limit,
            },
            None => Error::Parse {
                field: "recording".into(),
                reason: e.to_string(),
            },
        }
    }
}

#[derive(Debug, Clone, Copy, PartialEq)]
enum Separator {
    Char(char),
    Blank,
}

#[derive(Debug, Clone)]
struct Header {
    names: Vec<String>,
    time: usize,
    separator: Separator,
    klipper: bool,
    spectrum: Option<SpectrumLayout>,
    /// A RepRapFirmware accelerometer file: its channels' names (`accel_x` …).
    rrf: Option<Vec<String>>,
}

/// A shaper column's name and frequency: `zv(59.8)` (`save_calibration_data` writes
/// `%s(%.1f)`); `None` for any other column name.
fn shaper_label(name: &str) -> Option<(String, f64)> {
    name.strip_suffix(')')
        .and_then(|s| s.split_once('('))
        .filter(|(a, _)| !a.is_empty())
        .and_then(|(a, f)| {
            f.parse::<f64>()
                .ok()
                .filter(|f| f.is_finite())
                .map(|f| (a.to_string(), f))
        })
}

/// Where the columns of a Klipper spectrum file are.
#[derive(Debug, Clone)]
struct SpectrumLayout {
    /// Index of the `shapers:` column.
    marker: Option<usize>,
    /// Columns between `psd_xyz` and the marker (or the end).
    extra: Vec<usize>,
    /// The shapers' (column, name, frequency).
    shapers: Vec<(usize, String, f64)>,
    /// The columns between `freq` and `shapers:` are runs (`psd_xyz` each), not x, y, z, sum.
    runs: bool,
}

/// What a file held: a recording or a spectrum.
#[derive(Debug, Clone, PartialEq)]
pub enum Parsed {
    /// A time series.
    Recording(Recording),
    /// A Klipper spectrum file.
    Spectrum(SpectrumFile),
}

/// An incremental CSV reader: [`push`](RecordingParser::push) text in chunks of any size
/// (lines may span chunks), then [`finish`](RecordingParser::finish).
#[derive(Debug, Clone)]
pub struct RecordingParser {
    options: RecordingOptions,
    pending: String,
    line: usize,
    header: Option<Header>,
    times: Vec<f64>,
    columns: Vec<Vec<f64>>,
    failed: Option<RecordingError>,
    header_line_seen: usize,
    /// A RepRapFirmware file's last line: (its line, the rate in Hz).
    rrf_rate: Option<(usize, f64)>,
}

/// The value in column `column` (1-based, named `name`) of line `n`: present, a number,
/// finite.
fn value_of(n: usize, column: usize, name: &str, field: &str) -> Result<f64, RecordingError> {
    if field.is_empty() {
        return Err(RecordingError::field(n, column, name, "the value is empty"));
    }
    let value: f64 = field.parse().map_err(|_| {
        RecordingError::field(n, column, name, format!("`{field}` is not a number"))
    })?;
    if !value.is_finite() {
        return Err(RecordingError::field(
            n,
            column,
            name,
            format!("`{field}` is not a finite number"),
        ));
    }
    Ok(value)
}

/// Why a header line without a time column is no header: a row of numbers, a `timeColumn`
/// option the header does not name, or no column of a time name.
fn no_time_column(names: &[String], wanted: Option<&str>) -> String {
    if names.iter().all(|s| s.parse::<f64>().is_ok()) {
        return "no header: the first line must name the columns, one of them the time \
                (e.g. `time,accel_x,accel_y,accel_z`)"
            .to_string();
    }
    let listed = names
        .iter()
        .map(|s| format!("`{s}`"))
        .collect::<Vec<_>>()
        .join(", ");
    match wanted {
        Some(w) => format!("no column named `{w}` (the header has {listed})"),
        None => format!(
            "no time column in the header ({listed}); name it `time` or give \
             its name as the timeColumn option"
        ),
    }
}

fn split(line: &str, sep: Separator) -> Vec<&str> {
    match sep {
        Separator::Char(c) => line.split(c).map(str::trim).collect(),
        Separator::Blank => line.split_whitespace().collect(),
    }
}

fn is_time_name(name: &str, wanted: Option<&str>) -> bool {
    match wanted {
        Some(w) => name.trim().eq_ignore_ascii_case(w.trim()),
        None => TIME_NAMES.iter().any(|n| name.eq_ignore_ascii_case(n)),
    }
}

impl RecordingParser {
    /// A parser with `options`.
    pub fn new(options: RecordingOptions) -> Self {
        RecordingParser {
            options,
            pending: String::new(),
            line: 0,
            header: None,
            times: Vec::new(),
            columns: Vec::new(),
            failed: None,
            header_line_seen: 0,
            rrf_rate: None,
        }
    }

    /// Lines read so far.
    pub fn lines(&self) -> usize {
        self.line
    }

    /// Data rows read so far.
    pub fn rows(&self) -> usize {
        self.times.len()
    }

    /// Reads a chunk of text. After an error every further call returns the same error.
    pub fn push(&mut self, chunk: &str) -> Result<(), RecordingError> {
        if let Some(e) = &self.failed {
            return Err(e.clone());
        }
        let result = self.push_inner(chunk).map_err(|e| self.located(e));
        if let Err(e) = &result {
            self.failed = Some(e.clone());
        }
        result
    }

    fn located(&self, mut e: RecordingError) -> RecordingError {
        if e.file.is_none() {
            e.file = self.options.file_name.clone();
        }
        e
    }

    fn push_inner(&mut self, chunk: &str) -> Result<(), RecordingError> {
        let mut rest = chunk;
        while let Some(i) = rest.find('\n') {
            let (head, tail) = rest.split_at(i);
            rest = &tail[1..];
            if self.pending.is_empty() {
                self.line(head)?;
            } else {
                let mut full = std::mem::take(&mut self.pending);
                full.push_str(head);
                self.line(&full)?;
            }
        }
        self.pending.push_str(rest);
        if self.pending.len() > MAX_LINE_BYTES {
            let mut e = RecordingError::at(
                self.line + 1,
                format!("the line is longer than {MAX_LINE_BYTES} bytes — is this a CSV file?"),
            );
            e.too_large = Some((self.pending.len() as f64, MAX_LINE_BYTES as f64));
            return Err(e);
        }
        Ok(())
    }

    fn line(&mut self, raw: &str) -> Result<(), RecordingError> {
        self.line += 1;
        let n = self.line;
        if raw.len() > MAX_LINE_BYTES {
            let mut e = RecordingError::at(
                n,
                format!("the line is longer than {MAX_LINE_BYTES} bytes — is this a CSV file?"),
            );
            e.too_large = Some((raw.len() as f64, MAX_LINE_BYTES as f64));
            return Err(e);
        }
        let text = raw.trim_end_matches('\r').trim();
        let text = if n == 1 {
            text.trim_start_matches('\u{feff}')
        } else {
            text
        };
        if text.is_empty() {
            return Ok(());
        }
        if self.header.is_none() {
            return self.header_line(text);
        }
        if text.starts_with('#') {
            return Ok(());
        }
        if self.header.as_ref().is_some_and(|h| h.rrf.is_some()) {
            return self.rrf_line(n, text);
        }
        self.row(n, text)
    }

    /// A line of a RepRapFirmware accelerometer file after its header: a data row, the last
    /// line `Rate <Hz>, overflows <n>`, or one of the firmware's messages where the data
    /// stopped (`Failed to collect data from accelerometer`, `Data incomplete`, `Received bad
    /// data`, …).
    fn rrf_line(&mut self, n: usize, text: &str) -> Result<(), RecordingError> {
        if let Some((line, _)) = self.rrf_rate {
            return Err(RecordingError::at(
                n,
                format!("nothing may follow RepRapFirmware's `Rate …` line (line {line})"),
            ));
        }
        if text.starts_with(|c: char| c.is_ascii_digit()) {
            return self.row(n, text);
        }
        let Some((rate, overflows)) = rrf_trailer(text) else {
            return Err(RecordingError::at(
                n,
                format!("RepRapFirmware wrote `{text}` here: the recording is incomplete"),
            ));
        };
        if overflows > 0 {
            return Err(RecordingError::at(
                n,
                format!(
                    "the accelerometer's buffer overflowed {overflows} time{} during this \
                     recording (`{text}`): samples are missing, so its times and frequencies \
                     would be wrong; record again at a lower rate (M955 S) or with fewer samples",
                    if overflows == 1 { "" } else { "s" }
                ),
            ));
        }
        if !(rate.is_finite() && rate > 0.0) {
            return Err(RecordingError::at(
                n,
                format!("the sample rate must be positive, got `{text}`"),
            ));
        }
        self.rrf_rate = Some((n, rate));
        Ok(())
    }

    /// A data row (line `n`, trimmed, after the header): its values checked and stored.
    fn row(&mut self, n: usize, text: &str) -> Result<(), RecordingError> {
        let Some(header) = &self.header else {
            return Ok(());
        };
        let fields = split(text, header.separator);
        let count = if fields.len() == header.names.len() + 1 && fields.last() == Some(&"") {
            header.names.len()
        } else {
            fields.len()
        };
        if count != header.names.len() {
            return Err(RecordingError::at(
                n,
                format!(
                    "{} values, but the header on line {} names {} columns",
                    fields.len(),
                    self.header_line_number(),
                    header.names.len()
                ),
            ));
        }
        if self.times.len() >= MAX_ROWS {
            let mut e = RecordingError::at(n, format!("more than {MAX_ROWS} data rows"));
            e.too_large = Some(((MAX_ROWS + 1) as f64, MAX_ROWS as f64));
            return Err(e);
        }
        let mut signal = 0;
        let marker = header.spectrum.as_ref().and_then(|s| s.marker);
        for (j, field) in fields.iter().take(count).enumerate() {
            let name = &header.names[j];
            if Some(j) == marker {
                if !field.is_empty() {
                    return Err(RecordingError::field(
                        n,
                        j + 1,
                        name,
                        format!("the `shapers:` column should be empty, got `{field}`"),
                    ));
                }
                continue;
            }
            let value = value_of(n, j + 1, name, field)?;
            if let Some(layout) = &header.spectrum {
                if j == 0 {
                    if let Some(&prev) = self.times.last() {
                        if value <= prev {
                            return Err(RecordingError::field(
                                n,
                                1,
                                name,
                                format!("frequency {field} does not increase (the previous row has {prev})"),
                            ));
                        }
                    }
                    self.times.push(value);
                } else {
                    let is_psd = if layout.runs {
                        layout.extra.contains(&j)
                    } else {
                        (1..=4).contains(&j)
                    };
                    if is_psd && value < 0.0 {
                        return Err(RecordingError::field(
                            n,
                            j + 1,
                            name,
                            format!("a PSD cannot be negative, got {field}"),
                        ));
                    }
                    self.columns[signal].push(value);
                    signal += 1;
                }
                continue;
            }
            if j == header.time {
                let t = value * self.options.time_scale;
                if let Some(&prev) = self.times.last() {
                    if t <= prev {
                        return Err(RecordingError::field(
                            n,
                            j + 1,
                            name,
                            format!(
                                "time {field} does not increase (the previous row has {})",
                                prev / self.options.time_scale
                            ),
                        ));
                    }
                }
                self.times.push(t);
            } else {
                self.columns[signal].push(value);
                signal += 1;
            }
        }
        Ok(())
    }

    fn header_line_number(&self) -> usize {
        // Only used in messages: the header is the first line that made `header` Some.
        self.header_line_seen
    }

    fn header_line(&mut self, text: &str) -> Result<(), RecordingError> {
        let n = self.line;
        let commented = text.starts_with('#');
        let body = text.trim_start_matches('#').trim();
        let separator = if body.contains(',') {
            Separator::Char(',')
        } else if body.contains(';') {
            Separator::Char(';')
        } else if body.contains('\t') {
            Separator::Char('\t')
        } else {
            Separator::Blank
        };
        let names: Vec<String> = split(body, separator)
            .into_iter()
            .map(|s| s.trim_matches('"').to_string())
            .collect();
        if names.len() >= 5
            && names[..5]
                .iter()
                .zip(["freq", "psd_x", "psd_y", "psd_z", "psd_xyz"])
                .all(|(a, b)| a.eq_ignore_ascii_case(b))
        {
            return self.spectrum_header(names, separator);
        }
        if names
            .first()
            .is_some_and(|s| s.eq_ignore_ascii_case("freq"))
            && names.len() >= 2
        {
            // Klipper's current `save_calibration_data` with several runs: one `psd_xyz`
            // column per run, named after it.
            return self.spectrum_header(names, separator);
        }
        let wanted = self.options.time_column.as_deref();
        if let Some(channels) = rrf_channels(&names).filter(|_| wanted.is_none()) {
            self.columns = vec![Vec::new(); names.len() - 1];
            self.header = Some(Header {
                names,
                time: 0,
                separator,
                klipper: false,
                spectrum: None,
                rrf: Some(channels),
            });
            self.header_line_seen = n;
            return Ok(());
        }
        let time = names.iter().position(|s| is_time_name(s, wanted));
        let Some(time) = time else {
            if commented {
                return Ok(()); // a comment before the header
            }
            let reason = no_time_column(&names, wanted);
            return Err(RecordingError::at(n, reason));
        };
        if names.len() < 2 {
            return Err(RecordingError::at(
                n,
                "the header names only a time column; at least one signal column is needed",
            ));
        }
        if names.len() > MAX_COLUMNS {
            let mut e = RecordingError::at(n, format!("more than {MAX_COLUMNS} columns"));
            e.too_large = Some((names.len() as f64, MAX_COLUMNS as f64));
            return Err(e);
        }
        if let Some((j, name)) = names.iter().enumerate().find(|(_, s)| s.is_empty()) {
            return Err(RecordingError::field(
                n,
                j + 1,
                name,
                "the header leaves this column unnamed",
            ));
        }
        if !(self.options.time_scale.is_finite() && self.options.time_scale > 0.0) {
            return Err(RecordingError::at(
                0,
                format!(
                    "timeScale must be a positive number, got {}",
                    self.options.time_scale
                ),
            ));
        }
        let klipper = names.len() == 4
            && names
                .iter()
                .zip(["time", "accel_x", "accel_y", "accel_z"])
                .all(|(a, b)| a == b);
        self.columns = vec![Vec::new(); names.len() - 1];
        self.header = Some(Header {
            names,
            time,
            separator,
            klipper,
            spectrum: None,
            rrf: None,
        });
        self.header_line_seen = n;
        Ok(())
    }

    fn spectrum_header(
        &mut self,
        names: Vec<String>,
        separator: Separator,
    ) -> Result<(), RecordingError> {
        let n = self.line;
        if names.len() > MAX_COLUMNS {
            let mut e = RecordingError::at(n, format!("more than {MAX_COLUMNS} columns"));
            e.too_large = Some((names.len() as f64, MAX_COLUMNS as f64));
            return Err(e);
        }
        // Klipper writes the names in lower case; other tools' `Freq,PSD_X,…` read the same.
        let marker = names
            .iter()
            .position(|s| s.eq_ignore_ascii_case("shapers:"));
        let runs = !names
            .get(1)
            .is_some_and(|s| s.eq_ignore_ascii_case("psd_x"));
        let first_extra = if runs { 1 } else { 5 };
        // Klipper's releases before the `shapers:` marker (2021–2023, `save_calibration_data`
        // writing `freq,psd_x,psd_y,psd_z,psd_xyz,zv(61.6),mzv(62.6),…`): the trailing columns
        // named `<shaper>(<frequency>)` are the fitted shapers, on the PSD's own rows.
        let unmarked = if marker.is_none() && !runs {
            let tail = names[first_extra.min(names.len())..]
                .iter()
                .rev()
                .take_while(|s| shaper_label(s).is_some())
                .count();
            (tail > 0).then(|| names.len() - tail)
        } else {
            None
        };
        let end = marker.or(unmarked).unwrap_or(names.len());
        let extra: Vec<usize> = (first_extra..end).collect();
        if runs && extra.is_empty() {
            return Err(RecordingError::at(
                n,
                "a spectrum file needs at least one PSD column after `freq`",
            ));
        }
        let mut shapers = Vec::new();
        if let Some(first) = marker.map(|m| m + 1).or(unmarked) {
            for (j, name) in names.iter().enumerate().skip(first) {
                let Some((shaper, freq)) = shaper_label(name) else {
                    return Err(RecordingError::field(
                        n,
                        j + 1,
                        name,
                        "a shaper column must be named `<shaper>(<frequency>)`, e.g. `mzv(52.4)`",
                    ));
                };
                shapers.push((j, shaper, freq));
            }
        }
        if let Some((j, name)) = names.iter().enumerate().find(|(_, s)| s.is_empty()) {
            return Err(RecordingError::field(
                n,
                j + 1,
                name,
                "the header leaves this column unnamed",
            ));
        }
        self.columns = vec![Vec::new(); names.len() - 1 - usize::from(marker.is_some())];
        self.header = Some(Header {
            names,
            time: 0,
            separator,
            klipper: true,
            spectrum: Some(SpectrumLayout {
                marker,
                extra,
                shapers,
                runs,
            }),
            rrf: None,
        });
        self.header_line_seen = n;
        Ok(())
    }

    /// Reads whatever is left, checks the recording and puts it on an even grid. A spectrum
    /// file is an error here (read it with [`finish_any`](RecordingParser::finish_any)).
    pub fn finish(self) -> Result<Recording, RecordingError> {
        let line = self.header_line_seen;
        match self.finish_any()? {
            Parsed::Recording(r) => Ok(r),
            Parsed::Spectrum(s) => Err(RecordingError {
                file: s.file_name.clone(),
                ..RecordingError::at(
                    line,
                    "this is a Klipper spectrum file, not a recording with a time column",
                )
            }),
        }
    }

    /// Reads whatever is left: a recording (see [`finish`](RecordingParser::finish)) or a
    /// Klipper spectrum file.
    pub fn finish_any(self) -> Result<Parsed, RecordingError> {
        let file = self.options.file_name.clone();
        self.finish_inner().map_err(|mut e| {
            if e.file.is_none() {
                e.file = file;
            }
            e
        })
    }

    fn finish_inner(mut self) -> Result<Parsed, RecordingError> {
        if let Some(e) = self.failed.take() {
            return Err(e);
        }
        if !self.pending.is_empty() {
            let last = std::mem::take(&mut self.pending);
            self.line(&last)?;
        }
        let Some(header) = self.header.take() else {
            return Err(RecordingError::at(
                self.line.max(1),
                if self.line == 0 {
                    "the file is empty"
                } else {
                    "the file has no header line naming the columns"
                },
            ));
        };
        let n = self.times.len();
        if let Some(layout) = header.spectrum.clone() {
            return self.finish_spectrum(header, layout).map(Parsed::Spectrum);
        }
        if n < 2 {
            return Err(RecordingError::at(
                self.line.max(1),
                format!(
                    "{} data row{}: at least 2 are needed (a spectrum needs many more)",
                    n,
                    if n == 1 { "" } else { "s" }
                ),
            ));
        }
        if header.rrf.is_some() {
            self.rrf_to_seconds()?;
        }
        let t0 = self.times[0];
        let duration = self.times[n - 1] - t0;
        let mean = duration / (n - 1) as f64;
        let (mut lo, mut hi, mut ss) = (f64::INFINITY, 0.0_f64, 0.0);
        for w in self.times.windows(2) {
            let d = w[1] - w[0];
            lo = lo.min(d);
            hi = hi.max(d);
            ss += (d - mean) * (d - mean);
        }
        let jitter = (ss / (n - 1) as f64).sqrt() / mean;
        // Steps that differ by no more than the rounding of 6-decimal times (Klipper writes
        // `%.6f`: two roundings of 0.5 µs) or 0.1 % are even.
        let uneven = (hi - mean).max(mean - lo) > (1e-3 * mean).max(1.01e-6);
        let names = header.names;
        let signal_names: Vec<String> = match &header.rrf {
            Some(channels) => channels.clone(),
            None => names
                .iter()
                .enumerate()
                .filter(|(j, _)| *j != header.time)
                .map(|(_, name)| name.clone())
                .collect(),
        };
        let channels = self
            .columns
            .into_iter()
            .zip(signal_names)
            .map(|(values, name)| Channel {
                name,
                values: if uneven {
                    resample(&self.times, &values, mean)
                } else {
                    values
                },
            })
            .collect();
        Ok(Parsed::Recording(Recording {
            format: if header.rrf.is_some() {
                RecordingFormat::Rrf
            } else if header.klipper {
                RecordingFormat::Klipper
            } else {
                RecordingFormat::Csv
            },
            time_column: names[header.time].clone(),
            channels,
            sample_rate_hz: 1.0 / mean,
            start_time_s: t0,
            duration_s: duration,
            rows: n,
            resampled: uneven,
            timing: Timing {
                mean_step_s: mean,
                min_step_s: lo,
                max_step_s: hi,
                jitter,
            },
            time_s: if uneven {
                (0..n).map(|k| t0 + k as f64 * mean).collect()
            } else {
                self.times
            },
        }))
    }

    /// A RepRapFirmware file's sample numbers into seconds (over its `Rate` line's rate, or
    /// as `timeScale` already made them) and its values from g into mm/s².
    fn rrf_to_seconds(&mut self) -> Result<(), RecordingError> {
        let scaled = self.options.time_scale != 1.0;
        match self.rrf_rate {
            Some((_, rate)) if !scaled => self.times.iter_mut().for_each(|t| *t /= rate),
            Some(_) => {}
            None if scaled => {}
            None => {
                return Err(RecordingError::at(
                    self.line.max(1),
                    "RepRapFirmware's accelerometer file ends with `Rate <Hz>, overflows <n>`; \
                     this one has no such line (cut short?), so its sample rate is unknown: \
                     give the sample period as the timeScale option (1/rate, s)",
                ));
            }
        }
        for column in &mut self.columns {
            column.iter_mut().for_each(|v| *v *= G_MM_S2);
        }
        Ok(())
    }

    fn finish_spectrum(
        self,
        header: Header,
        layout: SpectrumLayout,
    ) -> Result<SpectrumFile, RecordingError> {
        let n = self.times.len();
        if n < 2 {
            return Err(RecordingError::at(
                self.line.max(1),
                format!(
                    "{n} frequency row{}: a spectrum needs at least 2 bins",
                    if n == 1 { "" } else { "s" }
                ),
            ));
        }
        // Data columns are the header's less `freq` and the `shapers:` marker.
        let data_index = |j: usize| j - 1 - usize::from(layout.marker.is_some_and(|m| j > m));
        let mut cols = self.columns;
        let take = |cols: &mut Vec<Vec<f64>>, j: usize| std::mem::take(&mut cols[data_index(j)]);
        let (psd_x, psd_y, psd_z, psd_sum) = if layout.runs {
            (Vec::new(), Vec::new(), Vec::new(), Vec::new())
        } else {
            (
                take(&mut cols, 1),
                take(&mut cols, 2),
                take(&mut cols, 3),
                take(&mut cols, 4),
            )
        };
        let extra: Vec<Channel> = layout
            .extra
            .iter()
            .map(|&j| Channel {
                name: header.names[j].clone(),
                values: take(&mut cols, j),
            })
            .collect();
        let shapers: Vec<FittedShaper> = layout
            .shapers
            .iter()
            .map(|(j, name, f)| FittedShaper {
                name: name.clone(),
                frequency_hz: *f,
                values: take(&mut cols, *j),
            })
            .collect();
        // As `calibrate_shaper.py`'s `parse_log`: a file with fitted shapers was normalised.
        let normalized = !shapers.is_empty() || header.names.iter().any(|s| s.contains("mzv"));
        let (resolution_hz, even) = resolution(&self.times);
        let (runs, extra) = if layout.runs {
            (extra, Vec::new())
        } else {
            (Vec::new(), extra)
        };
        let (psd_sum, channel) = if layout.runs {
            let k = runs.len() as f64;
            let mean = (0..n)
                .map(|i| runs.iter().map(|r| r.values[i]).sum::<f64>() / k)
                .collect();
            (mean, SpectrumChannel::Sum)
        } else {
            (psd_sum, self.options.channel)
        };
        let sources = runs.len().max(1);
        let file = SpectrumFile {
            format: if layout.marker.is_some() || !layout.shapers.is_empty() {
                RecordingFormat::KlipperCalibration
            } else {
                RecordingFormat::KlipperResonances
            },
            file_name: self.options.file_name.clone(),
            axis: self
                .options
                .file_name
                .as_deref()
                .and_then(axis_from_file_name),
            frequency_hz: self.times,
            psd_x,
            psd_y,
            psd_z,
            psd_sum,
            psd: Vec::new(),
            channel,
            normalization: if normalized {
                Normalization::Klipper
            } else {
                Normalization::None
            },
            resolution_hz,
            even,
            shapers,
            extra,
            runs,
            sources,
            segment_length: None,
        };
        Ok(file.with_channel(channel))
    }
}

/// Cubic Hermite interpolation of (t, v) onto t₀ + k·step, k < t.len(): exact at the samples,
/// continuous slope, third order on smooth signals on an uneven grid.
fn resample(t: &[f64], v: &[f64], step: f64) -> Vec<f64> {
    let n = t.len();
    let t0 = t[0];
    let mut j = 0; // t[j] ≤ x < t[j+1]
    (0..n)
        .map(|k| {
            let x = if k + 1 == n {
                t[n - 1]
            } else {
                t0 + k as f64 * step
            };
            while j + 2 < n && t[j + 1] <= x {
                j += 1;
            }
            let (ta, tb) = (t[j], t[j + 1]);
            let h = tb - ta;
            let s = ((x - ta) / h).clamp(0.0, 1.0);
            // Slopes of the parabola through three neighbours (exact for quadratics on an
            // uneven grid; one-sided at the ends).
            let slope = |i: usize| -> f64 {
                if i == 0 {
                    (v[1] - v[0]) / (t[1] - t[0])
                } else if i + 1 == n {
                    (v[n - 1] - v[n - 2]) / (t[n - 1] - t[n - 2])
                } else {
                    let (hl, hr) = (t[i] - t[i - 1], t[i + 1] - t[i]);
                    (hl * hl * (v[i + 1] - v[i]) + hr * hr * (v[i] - v[i - 1]))
                        / (hl * hr * (hl + hr))
                }
            };
            let (ma, mb) = (slope(j) * h, slope(j + 1) * h);
            let s2 = s * s;
            let s3 = s2 * s;
            (2.0 * s3 - 3.0 * s2 + 1.0) * v[j]
                + (s3 - 2.0 * s2 + s) * ma
                + (-2.0 * s3 + 3.0 * s2) * v[j + 1]
                + (s3 - s2) * mb
        })
        .collect()
}

/// Parses a whole file at once: a recording or a Klipper spectrum file.
pub fn parse_file(text: &str, options: &RecordingOptions) -> Result<Parsed, RecordingError> {
    let mut parser = RecordingParser::new(options.clone());
    parser.push(text)?;
    parser.finish_any()
}

/// Parses a whole recording at once (see the module docs).
pub fn parse_recording(
    text: &str,
    options: &RecordingOptions,
) -> Result<Recording, RecordingError> {
    let mut parser = RecordingParser::new(options.clone());
    parser.push(text)?;
    parser.finish()
}

/// Writes a recording as CSV: Klipper's raw format (`#time,accel_x,accel_y,accel_z`, values
/// with 6 decimals, as Klipper's `write_to_file`) when `format` is Klipper, else a header
/// `time,<names>` and values with 10 significant digits. Times are [`Recording::time_s`].
pub fn write_csv(recording: &Recording) -> String {
    let mut out = String::with_capacity(recording.rows * 12 * (recording.channels.len() + 1));
    let klipper = recording.format == RecordingFormat::Klipper;
    if klipper {
        out.push('#');
    }
    out.push_str(&recording.time_column);
    for c in &recording.channels {
        out.push(',');
        out.push_str(&c.name);
    }
    out.push('\n');
    use std::fmt::Write;
    for (k, &t) in recording.time_s.iter().enumerate() {
        if klipper {
            let _ = write!(out, "{t:.6}");
            for c in &recording.channels {
                let _ = write!(out, ",{:.6}", c.values[k]);
            }
        } else {
            let _ = write!(out, "{t:.9e}");
            for c in &recording.channels {
                let _ = write!(out, ",{:.9e}", c.values[k]);
            }
        }
        out.push('\n');
    }
    out
}
