// What the page's modules share, in one object: the state being edited (state.js), the
// library's family table, the last good frame, and the two calls that redraw (main.js sets
// them when it starts).
import { DEFAULT_STATE, clone } from './state.js';

export const page = {
  /** The playground state: `{ modes, shapers, view }` (state.js). */
  state: clone(DEFAULT_STATE),
  /** The library's family table (`families()`): names, titles, parameters with their editors. */
  families: [],
  /** The families always designed by the solver (`solver: "always"`; a `"whenBounded"` one,
   * sampled, only with bounds: the error tells). */
  solvedFamilies: new Set(),
  /** The last frame drawn: `{ state, result, left, waiting }` (the shapers it left out). */
  lastGood: null,
  /** Records an edit (the URL, the history) and schedules a frame; `commit` ends a gesture. */
  changed() {},
  /** Schedules a frame (several in one animation frame make one update). */
  schedule() {},
};
