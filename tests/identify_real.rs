//! Issue 20 on real Klipper files that are not in the repository (their licences are unknown;
//! sources in benches/real_klipper_sources.md): `REAL_KLIPPER_DIR=/path cargo test --release
//! --test identify_real -- --ignored --nocapture`. Each spectrum file is read by the product's
//! reader (`parse_file`) and its modes identified (`identify_spectrum`, default options); the
//! table prints the modes, the sweep's end and a response cut off there, and the notes. Prints
//! only, and fails only when a file comes out with neither a mode nor a note (a file whose
//! spectrum shows something must never read as "no mode" without a word): the figures go to
//! docs/measured-data.md (*On real recordings*).

use input_shaping::measure::identify::{
    identify, identify_spectrum, Identification, IdentifyOptions,
};
use input_shaping::measure::recording::{parse_file, Parsed};
use input_shaping::measure::RecordingOptions;

#[test]
#[ignore = "needs REAL_KLIPPER_DIR: real files that are not in the repository"]
fn identify_real_files() {
    let Ok(dir) = std::env::var("REAL_KLIPPER_DIR") else {
        println!("REAL_KLIPPER_DIR is not set: nothing to do");
        return;
    };
    let mut files: Vec<_> = std::fs::read_dir(&dir)
        .unwrap()
        .filter_map(|e| e.ok().map(|e| e.path()))
        .filter(|p| p.extension().is_some_and(|x| x == "csv"))
        .collect();
    files.sort();
    let mut silent = Vec::new();
    for path in &files {
        let name = path.file_name().unwrap().to_string_lossy().to_string();
        let text = std::fs::read_to_string(path).unwrap();
        let options = RecordingOptions {
            file_name: Some(name.clone()),
            ..RecordingOptions::default()
        };
        let id = match parse_file(&text, &options) {
            Ok(Parsed::Spectrum(sf)) => identify_spectrum(&sf, &IdentifyOptions::default()),
            Ok(Parsed::Recording(r)) => identify_raw(&name, &r),
            Err(e) => {
                println!("{name}: not read: {e}");
                continue;
            }
        }
        .unwrap();
        let modes: Vec<String> = id
            .modes
            .iter()
            .map(|m| {
                format!(
                    "{:.1} Hz ζ {:.3} ({:.0} dB)",
                    m.frequency_hz, m.damping, m.prominence_db
                )
            })
            .collect();
        println!(
            "{name}: modes [{}]; sweep {}; sweep end {}; cut off {}",
            modes.join(", "),
            id.sweep.map_or("none".to_string(), |s| format!(
                "{:.1}–{:.1} Hz",
                s.band_hz[0], s.band_hz[1]
            )),
            id.sweep_end_hz
                .map_or("none".to_string(), |f| format!("{f:.1} Hz")),
            id.cut_off.map_or("none".to_string(), |c| format!(
                "≥ {:.1} Hz ({:.0} dB)",
                c.frequency_hz, c.prominence_db
            )),
        );
        for note in &id.notes {
            println!("    note: {note}");
        }
        if id.modes.is_empty() && id.notes.is_empty() {
            silent.push(name);
        }
    }
    assert!(silent.is_empty(), "no mode and no note: {silent:?}");
}

/// A raw recording (Klipper's `raw_data_<axis>_…csv`): the channel of the axis its name gives
/// (`x` when it names none), identified with the defaults but for the sample rate.
fn identify_raw(
    name: &str,
    r: &input_shaping::measure::recording::Recording,
) -> input_shaping::error::Result<Identification> {
    let axis = ["x", "y", "z"]
        .into_iter()
        .find(|a| name.contains(&format!("_{a}_")))
        .unwrap_or("x");
    let x = &r.channel(&format!("accel_{axis}")).unwrap().values;
    identify(x, &IdentifyOptions::new(r.sample_rate_hz))
}
