// The measured-data worker: reads a recording in chunks, identifies the modes and ranks the
// shapers off the page's thread, so a 10⁶-row file never freezes the page. Messages in:
// { type: 'module', module } (first: the page's compiled wasm module), { id, type: 'load', file,
// options }, { id, type: 'analyse', options } and { id, type: 'fft', channel }; out: progress,
// result ({ recording, identification, recommendation, rankingError }), fft ({ spectrum }) or
// error ({ message, line, column }). Reading and identifying use the worker's own small module
// (pkg/page/recording.js), and so does the ranking (recommendShaper moved there with Klipper's
// fit, off the page's first load). The page still hands over its own module, compiled.
import initRecording, { RecordingParser, identifyModes, fftSpectrum, recommendShaper } from '../pkg/page/recording.js';
import initPlayground from '../pkg/page/playground.js';

const CHUNK_BYTES = 1 << 20;
const ready = initRecording();
let designs = null; // the page's module, instantiated here
let recording = null; // the last good recording

function summary(r) {
  const { channels, ...rest } = r;
  return { ...rest, channels: channels.map((c) => c.name) };
}

async function read(id, file) {
  const parser = new RecordingParser({});
  const decoder = new TextDecoder('utf-8');
  try {
    for (let offset = 0; offset < file.size; offset += CHUNK_BYTES) {
      const bytes = await file.slice(offset, offset + CHUNK_BYTES).arrayBuffer();
      parser.push(decoder.decode(bytes, { stream: true }));
      postMessage({ id, type: 'progress', fraction: Math.min(1, (offset + bytes.byteLength) / Math.max(1, file.size)), rows: parser.rows });
    }
    parser.push(decoder.decode());
    return parser.finish();
  } finally {
    parser.free();
  }
}

function analyse(id, rec, options) {
  postMessage({ id, type: 'analysing', rows: rec.rows });
  const identification = identifyModes(rec, options);
  let recommendation = null;
  let rankingError = null;
  if (identification.modes.length > 0) {
    try {
      recommendation = recommendShaper(identification.spectrum, identification.modes, {});
    } catch (e) {
      rankingError = e?.message ?? String(e); // the modes stay shown; only the ranking is missing
    }
  }
  return { id, type: 'result', recording: summary(rec), identification, recommendation, rankingError };
}

onmessage = async ({ data }) => {
  const { id } = data;
  if (data.type === 'module') {
    designs = initPlayground(data.module ? { module_or_path: data.module } : undefined);
    return;
  }
  try {
    await ready;
    await (designs ??= initPlayground()); // without the page's module, fetch it
    if (data.type === 'load') {
      const rec = await read(id, data.file);
      const result = analyse(id, rec, data.options);
      recording = rec; // only once everything worked: a bad file leaves the last good one
      postMessage(result);
    } else if (data.type === 'analyse' && recording) {
      postMessage(analyse(id, recording, data.options));
    } else if (data.type === 'fft' && recording) {
      // The plain FFT magnitude of the whole channel (at most 2^22 samples), as |X|² for the chart.
      const values = recording.channels[data.channel]?.values ?? recording.channels[0].values;
      const s = fftSpectrum(values, { sampleRateHz: recording.sampleRateHz });
      const power = s.magnitude.map((m) => m * m);
      postMessage({ id, type: 'fft', spectrum: { frequencyHz: s.frequencyHz, psd: power } }, [power.buffer]);
    }
  } catch (e) {
    postMessage({ id, type: 'error', message: e?.message ?? String(e), line: e?.line, column: e?.column });
  }
};
