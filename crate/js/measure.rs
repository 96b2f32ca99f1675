//! The JavaScript API for measured data (issue 7): reading a recording, its spectrum, the
//! identified modes and the recommended shaper. Thin glue over [`crate::measure`]; long arrays
//! cross the boundary as `Float64Array`s (copying 10⁶ numbers into a typed array is far cheaper
//! than building a JS array). Errors are JS `Error`s with `kind` and `field` as in `wasm.rs`;
//! recording errors also carry `line` and `column` (1-based) and `columnName`.
//!
//! Each export belongs to a Cargo feature (`js-api`, `js-playground`, `js-recording`; see
//! Cargo.toml). A build with only some of them leaves helpers unused, hence the allow there.
#![cfg_attr(not(feature = "js-api"), allow(dead_code, unused_imports))]

use super::api::{from_js, js_error, set, to_js};
use super::args::{self, f64_vec};
use super::canvas::Canvas;
use crate::chart::{self, ChartStyle};
use crate::error::Error;
use crate::measure::identify::{identify, identify_spectrum, IdentifyOptions};
use crate::measure::psd::{fft_spectrum, welch, FftOptions, Psd, WelchOptions};
use crate::measure::recommend::{
    recommend, MeasuredMode, MeasuredSpectrum, RecommendOptions, SpectrumRun,
};
use crate::measure::recording::Parsed;
use crate::measure::recording::{self, Recording, RecordingError, RecordingOptions};
use crate::measure::spectrum_file::{Normalization, SpectrumFile};
use plotters::prelude::*;
use serde::Deserialize;
use wasm_bindgen::prelude::*;
use wasm_bindgen::JsCast;
use web_sys::HtmlCanvasElement;

/// A recording error as a JS `Error` with `line`, `column`, `columnName`.
fn recording_error(e: RecordingError) -> JsValue {
    let (line, column, name, file) = (e.line, e.column, e.column_name.clone(), e.file.clone());
    let js = js_error(Error::from(e));
    if let Some(obj) = js.dyn_ref::<js_sys::Object>() {
        let _ = js_sys::Reflect::set(obj, &"line".into(), &(line as f64).into());
        if let Some(c) = column {
            let _ = js_sys::Reflect::set(obj, &"column".into(), &(c as f64).into());
        }
        if let Some(n) = name {
            let _ = js_sys::Reflect::set(obj, &"columnName".into(), &n.into());
        }
        if let Some(f) = file {
            let _ = js_sys::Reflect::set(obj, &"file".into(), &f.into());
        }
    }
    js
}

/// Options object, `{}` when missing.
pub(super) fn options<T: serde::de::DeserializeOwned + Default + std::fmt::Debug>(
    value: JsValue,
    what: &str,
) -> Result<T, Error> {
    if value.is_undefined() || value.is_null() {
        Ok(T::default())
    } else {
        from_js(value, what)
    }
}

/// The keys of `welch`'s options.
const WELCH_KEYS: &[&str] = &[
    "sampleRateHz",
    "segmentLength",
    "overlap",
    "window",
    "kaiserBeta",
    "symmetricWindow",
    "detrend",
    "scaling",
    "preset",
];
/// The keys of `fftSpectrum`'s options.
const FFT_KEYS: &[&str] = &["sampleRateHz", "window", "kaiserBeta", "detrend"];
/// The keys of `identifyModes`' options checked after they are read (its `signal` option is an
/// enumeration checked as it is read; a `signal` error is the samples').
const IDENTIFY_KEYS: &[&str] = &[
    "sampleRateHz",
    "maxModes",
    "minFrequencyHz",
    "maxFrequencyHz",
    "minProminenceDb",
    "segmentLength",
    "freeDecay",
    "channel",
];
/// The keys of `recommendShaper`'s options.
const RECOMMEND_KEYS: &[&str] = &[
    "families",
    "criterion",
    "firmware",
    "maxRemainingVibration",
    "scv",
    "uncertaintySigmas",
    "minFrequencyHz",
    "maxFrequencyHz",
    "shapers",
    "dampingRatio",
    "maxSmoothing",
    "maxVibrations",
    "testDampingRatios",
    "shaperFrequencies",
    "shaperFrequencyRange",
];
/// The keys of `recommendShaper`'s spectrum.
const SPECTRUM_KEYS: &[&str] = &[
    "frequencyHz",
    "psd",
    "normalization",
    "channel",
    "psdX",
    "psdY",
    "psdZ",
    "psdSum",
    "runs",
];

/// An error of the library's own checks of an object argument, named from that argument
/// (issue 21: `options.sampleRateHz`, not `sampleRateHz`): the core functions name an
/// option by its key alone, so an error whose field starts with one of `keys` (the
/// argument's) is put `within` the argument's name; any other error is left as it is.
fn named_in(argument: &'static str, keys: &'static [&'static str]) -> impl Fn(Error) -> Error {
    move |e| {
        let head = e
            .field()
            .map(|f| f.split(['.', '[', ' ']).next().unwrap_or_default());
        if head.is_some_and(|h| keys.contains(&h)) {
            e.within(argument)
        } else {
            e
        }
    }
}

fn get(object: &JsValue, key: &str) -> JsValue {
    js_sys::Reflect::get(object, &key.into()).unwrap_or(JsValue::UNDEFINED)
}

fn recording_to_js(rec: &Recording) -> Result<JsValue, JsValue> {
    let out = js_sys::Object::new();
    set(&out, "format", &to_js(&rec.format)?)?;
    set(&out, "timeColumn", &rec.time_column.clone().into())?;
    set(&out, "sampleRateHz", &rec.sample_rate_hz.into())?;
    set(&out, "startTimeS", &rec.start_time_s.into())?;
    set(&out, "durationS", &rec.duration_s.into())?;
    set(&out, "rows", &(rec.rows as f64).into())?;
    set(&out, "resampled", &rec.resampled.into())?;
    set(&out, "timing", &to_js(&rec.timing)?)?;
    set(&out, "channels", &channels_to_js(&rec.channels)?.into())?;
    Ok(out.into())
}

fn channels_to_js(list: &[recording::Channel]) -> Result<js_sys::Array, JsValue> {
    let out = js_sys::Array::new();
    for c in list {
        let ch = js_sys::Object::new();
        set(&ch, "name", &c.name.clone().into())?;
        set(
            &ch,
            "values",
            &js_sys::Float64Array::from(c.values.as_slice()),
        )?;
        out.push(&ch);
    }
    Ok(out)
}

/// A Klipper spectrum file as the JS object `parseRecording` returns for it.
fn spectrum_to_js(s: &SpectrumFile) -> Result<JsValue, JsValue> {
    let out = js_sys::Object::new();
    let arr = |v: &[f64]| js_sys::Float64Array::from(v);
    set(&out, "format", &to_js(&s.format)?)?;
    set(&out, "fileName", &to_js(&s.file_name)?)?;
    set(&out, "axis", &to_js(&s.axis)?)?;
    set(&out, "frequencyHz", &arr(&s.frequency_hz))?;
    set(&out, "psdX", &arr(&s.psd_x))?;
    set(&out, "psdY", &arr(&s.psd_y))?;
    set(&out, "psdZ", &arr(&s.psd_z))?;
    set(&out, "psdSum", &arr(&s.psd_sum))?;
    set(&out, "psd", &arr(&s.psd))?;
    set(&out, "channel", &to_js(&s.channel)?)?;
    set(&out, "normalization", &to_js(&s.normalization)?)?;
    set(&out, "resolutionHz", &s.resolution_hz.into())?;
    set(&out, "even", &s.even.into())?;
    set(&out, "rows", &(s.frequency_hz.len() as f64).into())?;
    set(&out, "sources", &(s.sources as f64).into())?;
    let shapers = js_sys::Array::new();
    for sh in &s.shapers {
        let o = js_sys::Object::new();
        set(&o, "name", &sh.name.clone().into())?;
        set(&o, "frequencyHz", &sh.frequency_hz.into())?;
        set(&o, "values", &arr(&sh.values))?;
        shapers.push(&o);
    }
    set(&out, "shapers", &shapers)?;
    set(&out, "extra", &channels_to_js(&s.extra)?.into())?;
    set(&out, "runs", &channels_to_js(&s.runs)?.into())?;
    Ok(out.into())
}

fn parsed_to_js(p: &Parsed) -> Result<JsValue, JsValue> {
    match p {
        Parsed::Recording(r) => recording_to_js(r),
        Parsed::Spectrum(s) => spectrum_to_js(s),
    }
}

/// A spectrum object from JS (`{ frequencyHz, psd, normalization? }`) as a [`SpectrumFile`].
fn spectrum_from_js(value: &JsValue) -> Result<SpectrumFile, Error> {
    let frequency_hz = f64_vec(&get(value, "frequencyHz"), "spectrum.frequencyHz")?;
    let psd = f64_vec(&get(value, "psd"), "spectrum.psd")?;
    let normalization: Normalization = match get(value, "normalization") {
        v if v.is_undefined() || v.is_null() => Normalization::None,
        v => from_js(v, "spectrum.normalization")?,
    };
    let segment_length = get(value, "segmentLength").as_f64().map(|v| v as usize);
    let (resolution_hz, even) = crate::measure::spectrum_file::resolution_of(&frequency_hz);
    Ok(SpectrumFile {
        format: recording::RecordingFormat::KlipperResonances,
        file_name: get(value, "fileName").as_string(),
        axis: get(value, "axis").as_string(),
        psd_sum: psd.clone(),
        psd,
        psd_x: Vec::new(),
        psd_y: Vec::new(),
        psd_z: Vec::new(),
        frequency_hz,
        channel: Default::default(),
        normalization,
        resolution_hz,
        even,
        shapers: Vec::new(),
        extra: Vec::new(),
        runs: Vec::new(),
        sources: 1,
        segment_length,
    })
}

fn psd_to_js(psd: &Psd) -> Result<JsValue, JsValue> {
    let out = js_sys::Object::new();
    set(
        &out,
        "frequencyHz",
        &js_sys::Float64Array::from(psd.frequency_hz.as_slice()),
    )?;
    set(&out, "psd", &js_sys::Float64Array::from(psd.psd.as_slice()))?;
    set(&out, "segmentLength", &(psd.segment_length as f64).into())?;
    set(&out, "overlap", &(psd.overlap as f64).into())?;
    set(&out, "segments", &(psd.segments as f64).into())?;
    set(&out, "resolutionHz", &psd.resolution_hz.into())?;
    set(&out, "enbwBins", &psd.enbw_bins.into())?;
    set(&out, "sampleRateHz", &psd.sample_rate_hz.into())?;
    Ok(out.into())
}

/// `parseRecording(text, { timeColumn?, timeScale?, fileName?, channel? })` → for a recording
/// `{ format: 'klipper' | 'rrf' | 'csv', timeColumn, sampleRateHz, startTimeS, durationS, rows,
/// resampled, timing: { meanStepS, minStepS, maxStepS, jitter }, channels: [{ name, values:
/// Float64Array }] }`; for a Klipper spectrum file `{ format: 'klipperResonances' |
/// 'klipperCalibration', fileName, axis: 'x' | 'y' | 'z' | null, frequencyHz, psdX, psdY, psdZ,
/// psdSum, psd (Float64Arrays; psd is the chosen channel: 'x' | 'y' | 'z' | 'sum', default
/// 'sum'), channel, normalization: 'none' | 'klipper', resolutionHz, even, rows, sources,
/// shapers: [{ name, frequencyHz, values }], extra: [{ name, values }], runs: [{ name, values }]
/// }`. Errors carry `line`, `column`, `columnName` and `file` (the `fileName` option).
#[cfg(feature = "js-api")]
#[wasm_bindgen(js_name = parseRecording, unchecked_return_type = "ParsedRecording")]
pub fn parse_recording(
    #[wasm_bindgen(unchecked_param_type = "string")] text: JsValue,
    #[wasm_bindgen(unchecked_optional_param_type = "RecordingOptions | null")] options: JsValue,
) -> Result<JsValue, JsValue> {
    let text = args::string(&text, "text").map_err(js_error)?;
    let options: RecordingOptions = self::options(options, "options").map_err(js_error)?;
    let parsed = recording::parse_file(&text, &options).map_err(recording_error)?;
    parsed_to_js(&parsed)
}

/// `new RecordingParser({ timeColumn?, timeScale? })`: reads a recording in chunks —
/// `push(text)` any number of times (lines may span chunks), then `finish()` → the same object
/// as `parseRecording`. `lines` and `rows` say how far it got (for a progress bar).
#[cfg(feature = "js-recording")]
#[wasm_bindgen(js_name = RecordingParser)]
pub struct JsRecordingParser {
    inner: Option<recording::RecordingParser>,
}

#[cfg(feature = "js-recording")]
#[wasm_bindgen(js_class = RecordingParser)]
impl JsRecordingParser {
    /// A parser with the options of `parseRecording`.
    #[wasm_bindgen(constructor)]
    pub fn new(
        #[wasm_bindgen(unchecked_optional_param_type = "RecordingOptions | null")] options: JsValue,
    ) -> Result<JsRecordingParser, JsValue> {
        let options: RecordingOptions = self::options(options, "options").map_err(js_error)?;
        Ok(JsRecordingParser {
            inner: Some(recording::RecordingParser::new(options)),
        })
    }

    /// Reads a chunk of text; throws at the first bad line (and on every later call).
    pub fn push(
        &mut self,
        #[wasm_bindgen(unchecked_param_type = "string")] chunk: JsValue,
    ) -> Result<(), JsValue> {
        let chunk = args::string(&chunk, "chunk").map_err(js_error)?;
        match &mut self.inner {
            Some(p) => p.push(&chunk).map_err(recording_error),
            None => Err(js_error(Error::invalid(
                "recording",
                "finish() was already called",
            ))),
        }
    }

    /// Lines read so far.
    #[wasm_bindgen(getter)]
    pub fn lines(&self) -> f64 {
        self.inner.as_ref().map_or(0.0, |p| p.lines() as f64)
    }

    /// Data rows read so far.
    #[wasm_bindgen(getter)]
    pub fn rows(&self) -> f64 {
        self.inner.as_ref().map_or(0.0, |p| p.rows() as f64)
    }

    /// Ends the input and returns the recording (see `parseRecording`).
    #[wasm_bindgen(unchecked_return_type = "ParsedRecording")]
    pub fn finish(&mut self) -> Result<JsValue, JsValue> {
        let p = self
            .inner
            .take()
            .ok_or_else(|| js_error(Error::invalid("recording", "finish() was already called")))?;
        let parsed = p.finish_any().map_err(recording_error)?;
        parsed_to_js(&parsed)
    }
}

/// `welch(signal, { sampleRateHz, segmentLength?, overlap?, window?, kaiserBeta?,
/// symmetricWindow?, detrend?, scaling? })` → `{ frequencyHz, psd (Float64Array),
/// segmentLength, overlap, segments, resolutionHz, enbwBins, sampleRateHz }`; `signal` is a
/// `Float64Array` or an array of numbers. `{ preset: 'klipper', sampleRateHz }` takes
/// Klipper's settings instead. (In the recording module too: the page's measured-data worker
/// forms Klipper's spectra of raw recordings with it.)
#[cfg(feature = "js-recording")]
#[wasm_bindgen(js_name = welch, unchecked_return_type = "Psd")]
pub fn welch_js(
    #[wasm_bindgen(unchecked_param_type = "Signal")] signal: JsValue,
    #[wasm_bindgen(unchecked_param_type = "WelchOptions | KlipperWelchOptions")] options: JsValue,
) -> Result<JsValue, JsValue> {
    let x = f64_vec(&signal, "signal").map_err(js_error)?;
    let preset = get(&options, "preset").as_string();
    let opts: WelchOptions = if preset.as_deref() == Some("klipper") {
        let fs = get(&options, "sampleRateHz").as_f64().unwrap_or(f64::NAN);
        WelchOptions::klipper(fs)
    } else {
        from_js(options, "options").map_err(js_error)?
    };
    let psd = welch(&x, &opts)
        .map_err(named_in("options", WELCH_KEYS))
        .map_err(js_error)?;
    psd_to_js(&psd)
}

/// `fftSpectrum(signal, { sampleRateHz, window?, kaiserBeta?, detrend? })` → `{ frequencyHz,
/// magnitude (Float64Array), resolutionHz }`: the amplitude spectrum of the whole record.
#[cfg(feature = "js-recording")]
#[wasm_bindgen(js_name = fftSpectrum, unchecked_return_type = "AmplitudeSpectrum")]
pub fn fft_spectrum_js(
    #[wasm_bindgen(unchecked_param_type = "Signal")] signal: JsValue,
    #[wasm_bindgen(unchecked_param_type = "FftOptions")] options: JsValue,
) -> Result<JsValue, JsValue> {
    let x = f64_vec(&signal, "signal").map_err(js_error)?;
    let opts: FftOptions = from_js(options, "options").map_err(js_error)?;
    let s = fft_spectrum(&x, &opts)
        .map_err(named_in("options", FFT_KEYS))
        .map_err(js_error)?;
    let out = js_sys::Object::new();
    set(
        &out,
        "frequencyHz",
        &js_sys::Float64Array::from(s.frequency_hz.as_slice()),
    )?;
    set(
        &out,
        "magnitude",
        &js_sys::Float64Array::from(s.magnitude.as_slice()),
    )?;
    set(&out, "resolutionHz", &s.resolution_hz.into())?;
    Ok(out.into())
}

#[derive(Debug, Deserialize, Default)]
#[serde(rename_all = "camelCase", default)]
struct ChannelChoice {
    channel: Option<serde_json_like::ChannelKey>,
}

mod serde_json_like {
    use serde::de::{self, Deserialize, Deserializer, Visitor};
    use std::fmt;

    /// A channel by name or index.
    #[derive(Debug)]
    pub(super) enum ChannelKey {
        Index(usize),
        Name(String),
    }

    /// Read by hand rather than `#[serde(untagged)]`, whose buffered parser (serde's `Content`)
    /// would be compiled into the wasm for this one field (see crate/tagged.rs).
    impl<'de> Deserialize<'de> for ChannelKey {
        fn deserialize<D: Deserializer<'de>>(d: D) -> Result<Self, D::Error> {
            struct Key;
            impl<'de> Visitor<'de> for Key {
                type Value = ChannelKey;

                fn expecting(&self, f: &mut fmt::Formatter) -> fmt::Result {
                    f.write_str("a channel index (0, 1, …) or name")
                }

                fn visit_u64<E: de::Error>(self, v: u64) -> Result<ChannelKey, E> {
                    usize::try_from(v)
                        .map(ChannelKey::Index)
                        .map_err(|_| E::invalid_value(de::Unexpected::Unsigned(v), &self))
                }

                fn visit_i64<E: de::Error>(self, v: i64) -> Result<ChannelKey, E> {
                    match u64::try_from(v) {
                        Ok(v) => self.visit_u64(v),
                        Err(_) => Err(E::invalid_value(de::Unexpected::Signed(v), &self)),
                    }
                }

                fn visit_str<E: de::Error>(self, v: &str) -> Result<ChannelKey, E> {
                    Ok(ChannelKey::Name(v.to_string()))
                }

                fn visit_string<E: de::Error>(self, v: String) -> Result<ChannelKey, E> {
                    Ok(ChannelKey::Name(v))
                }
            }
            d.deserialize_any(Key)
        }
    }
}

/// `identifyModes(recording, options)`: `recording` is a spectrum (`{ frequencyHz, psd,
/// normalization?: 'none' | 'klipper', segmentLength? }`, e.g. what `parseRecording` returns for
/// a Klipper spectrum file: the modes are then fitted to its bins, see `identify_spectrum`), or
/// what `parseRecording` returns for a recording (then
/// `options.channel` picks a channel by name or index, default the first) or a plain signal
/// (`Float64Array` / number array, then `options.sampleRateHz` is required). Options as
/// `IdentifyOptions`: `{ sampleRateHz?, signal: 'acceleration' | 'velocity' | 'position',
/// maxModes, minFrequencyHz, maxFrequencyHz, minProminenceDb, segmentLength, freeDecay }`.
/// → `{ channel, modes: [{ frequencyHz, damping, frequencyUncertaintyHz, dampingUncertainty,
/// method, peakFrequencyHz, peakPsd, prominenceDb, estimates: [...] }], spectrum: { frequencyHz,
/// psd, … }, detectionSegmentLength, bandHz, freeDecay: { startS, endS, levelDb } | null,
/// sweep: { bandHz, rateHzPerS, law } | null, sweepEndHz, cutOff, notes }` (`sweep`: the
/// sweep read from a raw recording, `law` `'linear'` or `'exponential'` (`rateHzPerS` then at
/// the band's geometric centre), whose modes were then fitted on its whole-record
/// periodogram; `null` otherwise. `sweepEndHz`: a spectrum file's sweep end, the last bin
/// fitted before its cliff, or `null`. `cutOff: { frequencyHz, prominenceDb } | null`: a
/// response still rising there (or at a raw recording's `sweep` end), a mode peaking near or
/// past `frequencyHz` that the data do not hold (not in `modes`). `notes`: what could not be identified, in words for the user).
#[cfg(feature = "js-recording")]
#[wasm_bindgen(js_name = identifyModes, unchecked_return_type = "Identification")]
pub fn identify_modes(
    #[wasm_bindgen(unchecked_param_type = "Recording | SpectrumInput | Signal")] recording: JsValue,
    #[wasm_bindgen(unchecked_optional_param_type = "IdentifyOptions | null")] options: JsValue,
) -> Result<JsValue, JsValue> {
    if !(options.is_undefined() || options.is_null() || options.is_object()) {
        return Err(js_error(Error::Parse {
            field: "options".into(),
            reason: format!("must be an object, got {}", args::describe(&options)),
        }));
    }
    let is_spectrum = recording.is_object()
        && !get(&recording, "frequencyHz").is_undefined()
        && !get(&recording, "psd").is_undefined();
    if is_spectrum {
        let spectrum = spectrum_from_js(&recording).map_err(js_error)?;
        let opts = identify_options(&options).map_err(js_error)?;
        let id = identify_spectrum(&spectrum, &opts)
            .map_err(named_in("options", IDENTIFY_KEYS))
            .map_err(js_error)?;
        return identification_to_js(&id, get(&recording, "channel"), JsValue::NULL);
    }
    let choice: ChannelChoice = if options.is_object() {
        from_js(options.clone(), "options").map_err(js_error)?
    } else {
        ChannelChoice::default()
    };
    let mut opts = identify_options(&options).map_err(js_error)?;
    let (signal, name) = signal_to_identify(&recording, &choice, &mut opts).map_err(js_error)?;
    let id = identify(&signal, &opts)
        .map_err(named_in("options", IDENTIFY_KEYS))
        .map_err(js_error)?;
    let free_decay = to_js(&id.free_decay)?;
    identification_to_js(&id, name, free_decay)
}

/// `identifyModes`' options without `channel` (not an [`IdentifyOptions`] field: the others are
/// read from a copy without it).
fn identify_options(options: &JsValue) -> Result<IdentifyOptions, Error> {
    let copy = if options.is_object() {
        args::copy_object(options, "options")?
    } else {
        js_sys::Object::new()
    };
    let _ = js_sys::Reflect::delete_property(&copy, &"channel".into());
    from_js(copy.into(), "options")
}

/// The samples `identifyModes` reads from `recording` — a signal, or the chosen channel of
/// what `parseRecording` returns (whose `sampleRateHz` then fills in a missing
/// `options.sampleRateHz`) — and the channel's name (`null` for a signal).
fn signal_to_identify(
    recording: &JsValue,
    choice: &ChannelChoice,
    opts: &mut IdentifyOptions,
) -> Result<(Vec<f64>, JsValue), Error> {
    let is_signal = recording.is_instance_of::<js_sys::Float64Array>()
        || recording.is_instance_of::<js_sys::Float32Array>()
        || js_sys::Array::is_array(recording);
    if is_signal {
        return Ok((f64_vec(recording, "signal")?, JsValue::NULL));
    }
    let channels: js_sys::Array =
        get(recording, "channels")
            .dyn_into()
            .map_err(|_| Error::Parse {
                field: "recording.channels".into(),
                reason: "is missing: pass what parseRecording returns, or a signal".into(),
            })?;
    let index = match &choice.channel {
        None => 0,
        Some(serde_json_like::ChannelKey::Index(i)) => *i,
        Some(serde_json_like::ChannelKey::Name(n)) => channels
            .iter()
            .position(|c| get(&c, "name").as_string().as_deref() == Some(n.as_str()))
            .ok_or_else(|| Error::invalid("options.channel", format!("no channel named `{n}`")))?,
    };
    if index >= channels.length() as usize {
        return Err(Error::invalid(
            "options.channel",
            format!("the recording has {} channels", channels.length()),
        ));
    }
    let c = channels.get(index as u32);
    if opts.sample_rate_hz.is_nan() {
        opts.sample_rate_hz = get(recording, "sampleRateHz").as_f64().unwrap_or(f64::NAN);
    }
    let values = f64_vec(
        &get(&c, "values"),
        &format!("recording.channels[{index}].values"),
    )?;
    Ok((values, get(&c, "name")))
}

/// What `identifyModes` returns for `id`.
fn identification_to_js(
    id: &crate::measure::identify::Identification,
    channel: JsValue,
    free_decay: JsValue,
) -> Result<JsValue, JsValue> {
    let out = js_sys::Object::new();
    set(&out, "channel", &channel)?;
    set(&out, "modes", &to_js(&id.modes)?)?;
    set(&out, "spectrum", &psd_to_js(&id.spectrum)?)?;
    set(
        &out,
        "detectionSegmentLength",
        &(id.detection_segment_length as f64).into(),
    )?;
    set(&out, "bandHz", &to_js(&id.band_hz)?)?;
    set(&out, "freeDecay", &free_decay)?;
    let sweep = match &id.sweep {
        Some(sweep) => to_js(sweep)?,
        None => JsValue::NULL,
    };
    set(&out, "sweep", &sweep)?;
    let or_null = |v: Option<JsValue>| v.unwrap_or(JsValue::NULL);
    set(
        &out,
        "sweepEndHz",
        &or_null(id.sweep_end_hz.map(JsValue::from_f64)),
    )?;
    let cut_off = match &id.cut_off {
        Some(c) => Some(to_js(c)?),
        None => None,
    };
    set(&out, "cutOff", &or_null(cut_off))?;
    set(&out, "notes", &to_js(&id.notes)?)?;
    Ok(out.into())
}

/// `recommendShaper(spectrum, modes, options?)`: `spectrum = { frequencyHz, psd,
/// normalization?: 'none' | 'klipper', channel?: 'sum' | 'x' | 'y' | 'z', psdX?, psdY?, psdZ?,
/// psdSum?, runs?: [{ name, values }] }` (arrays or `Float64Array`s, e.g.
/// `identifyModes(…).spectrum` or a parsed Klipper spectrum file), `modes = [{ frequencyHz,
/// damping, frequencyUncertaintyHz?, dampingUncertainty? }]` (e.g. `identifyModes(…).modes`;
/// not used by `criterion: 'klipper'`), options `{ families?: [{ family, … }], criterion?:
/// 'duration' | 'klipper' | 'optimal', firmware?: 'klipper' | 'kalico' | 'reprapfirmware',
/// maxRemainingVibration?, scv?, uncertaintySigmas?, minFrequencyHz?,
/// maxFrequencyHz?, shapers?, dampingRatio?, maxSmoothing?, maxVibrations?,
/// testDampingRatios?, shaperFrequencies?, shaperFrequencyRange?: { start?, end?, step? } }` →
/// `{ criterion, recommended, ranked: [{ label, family, spec, modes, shaper, durationS,
/// remainingVibration, nominalRemainingVibration, smoothing, maxAccel, klipperScore,
/// acceptable }], dampingTested, frequencyFactors, bandHz, klipper? }` (`klipper`: Klipper's
/// table, see crate::measure::recommend). `criterion: 'optimal'`: the shaper optimised for the
/// spectrum by Klipper's own score, never worse than Klipper's pick (crate::measure::optimal) —
/// for `firmware: 'klipper'` the best mainline family × frequency × damping ratio, else a
/// custom impulse sequence within the firmware's limits — ranked first, then the rest of its
/// table (Klipper's own pick among them), with `note` saying what it bought. In the
/// measured-data worker's module (js-recording).
#[cfg(feature = "js-recording")]
#[wasm_bindgen(js_name = recommendShaper, unchecked_return_type = "Recommendation")]
pub fn recommend_shaper(
    #[wasm_bindgen(unchecked_param_type = "SpectrumInput")] spectrum: JsValue,
    #[wasm_bindgen(unchecked_optional_param_type = "MeasuredMode[] | null")] modes: JsValue,
    #[wasm_bindgen(unchecked_optional_param_type = "RecommendOptions | null")] options: JsValue,
) -> Result<JsValue, JsValue> {
    let spectrum = measured_spectrum(&spectrum).map_err(js_error)?;
    let modes: Vec<MeasuredMode> = if modes.is_undefined() || modes.is_null() {
        Vec::new()
    } else {
        from_js(modes, "modes").map_err(js_error)?
    };
    let options: RecommendOptions = self::options(options, "options").map_err(js_error)?;
    let r = recommend(&spectrum, &modes, &options)
        .map_err(named_in("options", RECOMMEND_KEYS))
        .map_err(named_in("spectrum", SPECTRUM_KEYS))
        .map_err(js_error)?;
    to_js(&r)
}

/// The spectrum object of `recommendShaper`, typed arrays accepted.
fn measured_spectrum(js: &JsValue) -> Result<MeasuredSpectrum, Error> {
    let optional = |key: &str| -> Result<Option<Vec<f64>>, Error> {
        let v = get(js, key);
        if v.is_undefined() || v.is_null() {
            Ok(None)
        } else {
            f64_vec(&v, &format!("spectrum.{key}")).map(Some)
        }
    };
    let tag = |key: &str| -> JsValue {
        let v = get(js, key);
        if v.is_null() {
            JsValue::UNDEFINED
        } else {
            v
        }
    };
    let mut runs = Vec::new();
    if let Some(list) = get(js, "runs").dyn_ref::<js_sys::Array>() {
        for (i, run) in list.iter().enumerate() {
            runs.push(SpectrumRun {
                name: get(&run, "name").as_string().unwrap_or_default(),
                values: f64_vec(&get(&run, "values"), &format!("spectrum.runs[{i}].values"))?,
            });
        }
    }
    let normalization = tag("normalization");
    let channel = tag("channel");
    Ok(MeasuredSpectrum {
        frequency_hz: f64_vec(&get(js, "frequencyHz"), "spectrum.frequencyHz")?,
        psd: f64_vec(&get(js, "psd"), "spectrum.psd")?,
        normalization: if normalization.is_undefined() {
            Default::default()
        } else {
            from_js(normalization, "spectrum.normalization")?
        },
        channel: if channel.is_undefined() {
            Default::default()
        } else {
            from_js(channel, "spectrum.channel")?
        },
        psd_x: optional("psdX")?,
        psd_y: optional("psdY")?,
        psd_z: optional("psdZ")?,
        psd_sum: optional("psdSum")?,
        runs,
    })
}

#[derive(Debug, Deserialize, Default)]
#[serde(rename_all = "camelCase", default)]
struct DrawOptions {
    peaks_hz: Vec<f64>,
    max_hz: Option<f64>,
    pixel_ratio: Option<f64>,
    title: Option<String>,
    y_label: Option<String>,
}

/// `drawSpectrum(canvas, spectrum, { peaksHz?, maxHz?, pixelRatio?, title?, yLabel? })`: draws
/// `spectrum = { frequencyHz, psd }` in dB (10·log₁₀ psd) on the canvas with a labelled marker
/// at each of `peaksHz`; `title` / `yLabel` default to "Measured spectrum (Welch PSD)" /
/// "PSD (dB)" (pass |X|² as `psd` to draw an FFT magnitude in dB).
#[cfg(feature = "js-playground")]
#[wasm_bindgen(js_name = drawSpectrum)]
pub fn draw_spectrum(
    #[wasm_bindgen(unchecked_param_type = "HTMLCanvasElement")] canvas: JsValue,
    #[wasm_bindgen(unchecked_param_type = "SpectrumInput")] spectrum: JsValue,
    #[wasm_bindgen(unchecked_optional_param_type = "DrawSpectrumOptions | null")] options: JsValue,
) -> Result<(), JsValue> {
    let canvas = args::canvas(canvas, "canvas").map_err(js_error)?;
    let f = f64_vec(&get(&spectrum, "frequencyHz"), "spectrum.frequencyHz").map_err(js_error)?;
    let p = f64_vec(&get(&spectrum, "psd"), "spectrum.psd").map_err(js_error)?;
    let o: DrawOptions = self::options(options, "options").map_err(js_error)?;
    let peaks: Vec<(f64, String)> = o
        .peaks_hz
        .iter()
        .map(|&f| (f, format!("{f:.2} Hz")))
        .collect();
    let (backend, style) = canvas_and_style(canvas, o.pixel_ratio)?;
    let titles = (
        o.title.as_deref().unwrap_or(chart::measured::PSD_TITLES.0),
        o.y_label
            .as_deref()
            .unwrap_or(chart::measured::PSD_TITLES.1),
    );
    chart::draw_measured_spectrum(
        &backend.into_drawing_area(),
        &f,
        &p,
        &peaks,
        o.max_hz,
        titles,
        &style,
    )
    .map_err(js_error)
}

/// The canvas's drawing backend and the chart style scaled by `pixel_ratio` (1 when absent or
/// not a positive number): what both measured-data charts start from.
pub(super) fn canvas_and_style(
    canvas: HtmlCanvasElement,
    pixel_ratio: Option<f64>,
) -> Result<(Canvas, ChartStyle), JsValue> {
    let style = ChartStyle {
        scale: pixel_ratio
            .filter(|r| r.is_finite() && *r > 0.0)
            .unwrap_or(1.0),
        ..ChartStyle::default()
    };
    let backend = Canvas::new(canvas).ok_or_else(|| {
        js_error(Error::Render {
            reason: "the canvas has no 2D context".into(),
        })
    })?;
    Ok((backend, style))
}

/// A `#rrggbb` colour.
#[cfg(feature = "js-recording")]
pub(super) fn css_hex(s: &str) -> Option<RGBColor> {
    let h = s.strip_prefix('#').filter(|h| h.len() == 6)?;
    let byte = |i: usize| u8::from_str_radix(h.get(i..i + 2)?, 16).ok();
    Some(RGBColor(byte(0)?, byte(2)?, byte(4)?))
}

#[cfg(feature = "js-recording")]
#[derive(Debug, Deserialize, Default)]
#[serde(rename_all = "camelCase", default)]
struct KlipperDrawOptions {
    max_hz: Option<f64>,
    pixel_ratio: Option<f64>,
    title: Option<String>,
}

/// `drawKlipperChart(canvas, { frequencyHz, psdSum, psdX?, psdY?, psdZ?, shapers?: [{ values,
/// color?: '#rrggbb', selected?, dotted? }], after? }, { maxHz?, pixelRatio?, title? })`: the
/// measured frequency response as Klipper's `calibrate_shaper.py` draws it — the PSDs on a
/// linear axis, each shaper's vibration ratio V(f) (`values`, one per frequency) on a second
/// axis 0 … 1, and the PSD after the `selected` shaper (`after`, or `psdSum`·V). Colours left
/// out are matplotlib's cycle, as in Klipper's figure; `maxHz` defaults to 200 (Klipper's).
#[cfg(feature = "js-recording")]
#[wasm_bindgen(js_name = drawKlipperChart)]
pub fn draw_klipper_chart(
    #[wasm_bindgen(unchecked_param_type = "HTMLCanvasElement")] canvas: JsValue,
    #[wasm_bindgen(unchecked_param_type = "KlipperChartData")] data: JsValue,
    #[wasm_bindgen(unchecked_optional_param_type = "KlipperChartOptions | null")] options: JsValue,
) -> Result<(), JsValue> {
    let canvas = args::canvas(canvas, "canvas").map_err(js_error)?;
    let vec = |key: &str| f64_vec(&get(&data, key), key).map_err(js_error);
    let optional = |key: &str| -> Result<Option<Vec<f64>>, JsValue> {
        let v = get(&data, key);
        if v.is_undefined() || v.is_null() {
            Ok(None)
        } else {
            f64_vec(&v, key).map(Some).map_err(js_error)
        }
    };
    let frequency_hz = vec("frequencyHz")?;
    let psd_sum = vec("psdSum")?;
    let (psd_x, psd_y, psd_z) = (optional("psdX")?, optional("psdY")?, optional("psdZ")?);
    let after = optional("after")?;
    let mut curves = Vec::new();
    let shapers = get(&data, "shapers");
    if let Some(list) = shapers.dyn_ref::<js_sys::Array>() {
        for (k, s) in list.iter().enumerate() {
            let values =
                f64_vec(&get(&s, "values"), &format!("shapers[{k}].values")).map_err(js_error)?;
            let color = get(&s, "color").as_string().and_then(|c| css_hex(&c));
            curves.push((
                values,
                color,
                get(&s, "selected").is_truthy(),
                get(&s, "dotted").is_truthy(),
            ));
        }
    }
    let o: KlipperDrawOptions = self::options(options, "options").map_err(js_error)?;
    let chart = chart::KlipperChart {
        frequency_hz: &frequency_hz,
        psd_sum: &psd_sum,
        psd_x: psd_x.as_deref(),
        psd_y: psd_y.as_deref(),
        psd_z: psd_z.as_deref(),
        shapers: curves
            .iter()
            .map(|(values, color, selected, dotted)| chart::ShaperCurve {
                values,
                color: *color,
                selected: *selected,
                dotted: *dotted,
            })
            .collect(),
        after: after.as_deref(),
        max_hz: o.max_hz,
        title: o.title.as_deref(),
    };
    let (backend, style) = canvas_and_style(canvas, o.pixel_ratio)?;
    chart::draw_klipper_chart(&backend.into_drawing_area(), &chart, &style).map_err(js_error)
}

/// `firmwareConfig({ firmware, axes })` → `{ text, warnings }`: the config text of the shaper
/// per axis for `firmware` — `"klipper"` (`[input_shaper]` block), `"klipperCommand"`
/// (`SET_INPUT_SHAPER`), `"kalico"`, `"kalicoCommand"` (custom shapers too), `"rrf"`
/// (RepRapFirmware 3.6 `M593`), `"marlin"` (ZV `M593`). `axes`: `[{ axis, family,
/// frequencyHz, damping, impulses, maxAccel, modes }]` (see
/// [`crate::export::firmware::AxisShaper`]). A shaper the firmware cannot express is an error
/// naming the field and the firmware's limit. In the measured-data worker's module.
#[cfg(feature = "js-recording")]
#[wasm_bindgen(js_name = firmwareConfig, unchecked_return_type = "FirmwareConfig")]
pub fn firmware_config_js(
    #[wasm_bindgen(unchecked_param_type = "FirmwareConfigRequest")] request: JsValue,
) -> Result<JsValue, JsValue> {
    use crate::export::firmware::{firmware_config, AxisShaper, Firmware};
    #[derive(Debug, Deserialize)]
    struct Request {
        firmware: Firmware,
        axes: Vec<AxisShaper>,
    }
    let r: Request = from_js(request, "request").map_err(js_error)?;
    to_js(&firmware_config(r.firmware, &r.axes).map_err(js_error)?)
}
