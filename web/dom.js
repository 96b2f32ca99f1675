// Small DOM helpers of the page (text only: user text never reaches innerHTML), the number
// formats of its tables and the series colours.

export const $ = (id) => document.getElementById(id);
/** The compared shapers' colours, by their index in the state. */
export const COLORS = ['#0072b2', '#d55e00', '#009e73', '#cc79a7'];

export function el(tag, props = {}, ...children) {
  const node = document.createElement(tag);
  for (const [k, v] of Object.entries(props)) {
    if (k === 'dataset') Object.assign(node.dataset, v);
    else if (k in node && typeof v !== 'string') node[k] = v;
    else node.setAttribute(k, v);
  }
  node.append(...children.filter((c) => c !== null && c !== undefined));
  return node;
}

export const fmt = (x, digits = 6) => (Number.isFinite(x) ? String(Number(x.toPrecision(digits))) : '—');
/** A vibration in %, with rounding-level values (below 1e-9 %) shown as ≈ 0. */
export const fmtPct = (fraction) => (Math.abs(fraction) < 1e-11 ? '≈ 0' : fmt(fraction * 100, 4));
export const readNumber = (input) => (input.value.trim() === '' ? NaN : Number(input.value));

/**
 * Makes `section` (a thead/tbody) hold `rows` — arrays of cell texts, the first `heads` cells
 * of each row `<th scope="row">`, the rest `<td>` — reusing the rows and cells already there
 * and writing only the texts that changed. Every input event redraws the tables; rebuilding
 * them made the browser restyle and lay out hundreds of new nodes per update. The texts last
 * written are remembered (`shownRows`), so unchanged cells are not read back from the DOM, and a
 * changed one has its text node's data replaced rather than a new node made.
 */
const shownRows = new WeakMap();
export function syncRows(section, rows, heads = 1) {
  while (section.rows.length > rows.length) section.deleteRow(-1);
  const shown = shownRows.get(section) ?? [];
  shown.length = Math.min(shown.length, section.rows.length);
  rows.forEach((cells, i) => {
    const tr = section.rows[i] ?? section.appendChild(document.createElement('tr'));
    const last = shown[i];
    if (!last || last.length !== cells.length || last.heads !== heads) {
      tr.replaceChildren(...cells.map((text, j) => (j < heads ? el('th', { scope: 'row' }, text) : el('td', {}, text))));
      shown[i] = Object.assign([...cells], { heads });
      return;
    }
    cells.forEach((text, j) => {
      if (last[j] === text) return;
      const cell = tr.cells[j];
      const node = cell.firstChild;
      if (node && node.nodeType === Node.TEXT_NODE && !node.nextSibling) node.data = text;
      else cell.textContent = text;
      last[j] = text;
    });
  });
  shownRows.set(section, shown);
}

/** Replaces `node`'s children with `build()` only when `key` differs from the last one used. */
export function rebuildIf(node, key, build) {
  if (node.dataset.key === key) return false;
  node.replaceChildren(...build());
  node.dataset.key = key;
  return true;
}

/** Says `text` in the page's notice line. */
export function notice(text) {
  $('notice').textContent = text;
}

/** Offers `text` as a file `name` to download. */
export function download(name, text) {
  const url = URL.createObjectURL(new Blob([text], { type: 'text/plain' }));
  const a = el('a', { href: url, download: name });
  document.body.append(a);
  a.click();
  a.remove();
  setTimeout(() => URL.revokeObjectURL(url), 1000);
}
