//! RepRapFirmware's accelerometer files (`M956`): read into mm/s² on Klipper's channel names,
//! their sample rate from the last line, and refused with the line and the reason where the
//! firmware says the data are incomplete. The layout is RepRapFirmware's own
//! (src/Accelerometers/Accelerometers.cpp: `CreateFile` writes `Sample,X,Y,Z`, each row is
//! `%u` then `,%.*f` per axis in g, the last line `Rate %u, overflows %u`); the files here are
//! written by hand in it.

use input_shaping::measure::identify::{identify, IdentifyOptions};
use input_shaping::measure::recording::{
    parse_file, parse_recording, Parsed, RecordingFormat, RecordingOptions, RecordingParser,
    G_MM_S2,
};
use wasm_bindgen_test::wasm_bindgen_test;

fn options() -> RecordingOptions {
    RecordingOptions {
        file_name: Some("0_2026-12-05_10.00.00.csv".into()),
        ..RecordingOptions::default()
    }
}

const THREE_AXES: &str = "Sample,X,Y,Z\n\
0,0.012,-0.004,1.002\n\
1,0.020,0.000,0.998\n\
2,-0.008,0.004,1.006\n\
3,0.000,-0.012,0.994\n\
Rate 1344, overflows 0\n";

#[wasm_bindgen_test(unsupported = test)]
fn a_reprapfirmware_file_is_read_in_mm_per_s2_at_its_rate() {
    let r = parse_recording(THREE_AXES, &options()).unwrap();
    assert_eq!(r.format, RecordingFormat::Rrf);
    assert_eq!(r.time_column, "Sample");
    assert_eq!(r.rows, 4);
    assert!(
        (r.sample_rate_hz - 1344.0).abs() < 1e-9,
        "{}",
        r.sample_rate_hz
    );
    assert!((r.duration_s - 3.0 / 1344.0).abs() < 1e-12);
    assert!(!r.resampled);
    let names: Vec<&str> = r.channels.iter().map(|c| c.name.as_str()).collect();
    assert_eq!(names, ["accel_x", "accel_y", "accel_z"]);
    // g → mm/s²: 1.002 g is 9825.26 mm/s².
    assert!((r.channel("accel_z").unwrap().values[0] - 1.002 * 9806.65).abs() < 1e-9);
    assert!((r.channel("accel_x").unwrap().values[2] + 0.008 * G_MM_S2).abs() < 1e-9);
    // One axis recorded (M956 … X), and the same text read in chunks across the rate line.
    let x = "Sample,X\n0,0.5\n1,0.25\n2,-0.25\nRate 400, overflows 0\n";
    let r = parse_recording(x, &options()).unwrap();
    assert_eq!(r.channels.len(), 1);
    assert_eq!(r.channels[0].name, "accel_x");
    assert!((r.sample_rate_hz - 400.0).abs() < 1e-9);
    let mut parser = RecordingParser::new(options());
    for chunk in [
        "Sample,X\n0,0.5\n1,0.2",
        "5\n2,-0.25\nRate 4",
        "00, overfl",
        "ows 0\n",
    ] {
        parser.push(chunk).unwrap();
    }
    assert_eq!(parser.finish().unwrap(), r);
    // Without the rate line, the sample period as `timeScale` gives the times.
    let cut = "Sample,X\n0,0.5\n1,0.25\n2,-0.25\n";
    let period = RecordingOptions {
        time_scale: 1.0 / 400.0,
        ..options()
    };
    let r = parse_recording(cut, &period).unwrap();
    assert_eq!(r.format, RecordingFormat::Rrf);
    assert!(
        (r.sample_rate_hz - 400.0).abs() < 1e-6,
        "{}",
        r.sample_rate_hz
    );
}

#[wasm_bindgen_test(unsupported = test)]
fn an_incomplete_reprapfirmware_file_is_refused_with_its_line() {
    let error = |text: &str| parse_file(text, &options()).unwrap_err();
    // Samples lost: the buffer overflowed.
    let e = error("Sample,X\n0,0.5\n1,0.25\n2,-0.25\nRate 1344, overflows 2\n");
    assert_eq!(e.line, 5);
    assert!(e.reason.contains("overflowed 2 times"), "{e}");
    assert!(!e.reason.contains("  "), "{e}");
    // The firmware's message where the data stopped.
    let e = error("Sample,X,Y,Z\n0,0.1,0.2,1.0\nFailed to collect data from accelerometer\n");
    assert_eq!(e.line, 3);
    assert!(e.reason.contains("Failed to collect data"), "{e}");
    assert_eq!(e.file.as_deref(), Some("0_2026-12-05_10.00.00.csv"));
    // No rate line and no timeScale: the sample rate is unknown.
    let e = error("Sample,X\n0,0.5\n1,0.25\n2,-0.25\n");
    assert!(e.reason.contains("timeScale"), "{e}");
    assert!(!e.reason.contains("  "), "{e}");
    // Rows after the rate line.
    let e = error("Sample,X\n0,0.5\n1,0.25\nRate 400, overflows 0\n2,0.1\n");
    assert_eq!(e.line, 5);
    // A bad value names its column.
    let e = error("Sample,X,Y\n0,0.5,0.1\n1,abc,0.2\nRate 400, overflows 0\n");
    assert_eq!(
        (e.line, e.column, e.column_name.as_deref()),
        (3, Some(2), Some("X"))
    );
    // Not RepRapFirmware's header (another column than X, Y, Z; an axis twice): read as any
    // CSV, which needs a time column.
    for header in ["Sample,X,Q", "Sample,X,X"] {
        let e = error(&format!("{header}\n0,1,2\n1,2,3\n"));
        assert!(e.reason.contains("no time column"), "{header}: {e}");
    }
}

/// The test set's raw Klipper recording of a 47.3 Hz, ζ 0.08 mode (issue 20's own example),
/// written as RepRapFirmware would (sample numbers, g to 4 decimals, an integer rate): the
/// same mode within issue 20's targets.
#[test]
fn a_sweep_recorded_by_reprapfirmware_gives_its_mode() {
    let path = format!(
        "{}/tests/data/klipper/raw_data_x_single47z08.csv",
        env!("CARGO_MANIFEST_DIR")
    );
    let klipper = match parse_file(&std::fs::read_to_string(path).unwrap(), &options()).unwrap() {
        Parsed::Recording(r) => r,
        Parsed::Spectrum(_) => panic!("a raw recording"),
    };
    let rate = klipper.sample_rate_hz.round();
    let x = &klipper.channel("accel_x").unwrap().values;
    let mut text = String::from("Sample,X\n");
    for (k, v) in x.iter().enumerate() {
        text.push_str(&format!("{k},{:.4}\n", v / G_MM_S2));
    }
    text.push_str(&format!("Rate {rate}, overflows 0\n"));
    let r = parse_recording(&text, &options()).unwrap();
    assert_eq!(r.format, RecordingFormat::Rrf);
    let id = identify(
        &r.channel("accel_x").unwrap().values,
        &IdentifyOptions::new(r.sample_rate_hz),
    )
    .unwrap();
    assert!(
        id.modes
            .iter()
            .any(|m| (m.frequency_hz / 47.3 - 1.0).abs() < 0.01
                && (m.damping / 0.08 - 1.0).abs() < 0.15),
        "{:?}",
        id.modes
    );
}
