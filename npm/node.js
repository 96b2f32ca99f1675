// The package's entry in Node (the "node" condition of its exports map; bundlers that target
// Node pick it too). Node's fetch does not read file: URLs, so the generated glue's `init()`
// could not load the wasm by itself: this file instantiates it synchronously from the
// input_shaping_bg.wasm next to it when imported. `init()` and `initSync()` stay exported and
// return at once, so one program imports and initialises the same way in Node and a browser.
import { readFileSync } from 'node:fs';
import { initSync } from './input_shaping.js';

initSync({ module: readFileSync(new URL('./input_shaping_bg.wasm', import.meta.url)) });

export * from './input_shaping.js';
export { default } from './input_shaping.js';
