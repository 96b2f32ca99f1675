// Lists the functions longer than a limit (default 100 lines, from the `fn` line to its closing
// brace) in crate/**/*.rs, longest first: `node scripts/long-functions.mjs [limit] [dir]`.
// Braces are matched outside comments, strings and char literals; `#[cfg(test)]` code counts
// too (a test's length is worth seeing as well).
import { readdirSync, readFileSync, statSync } from "node:fs";
import { join, relative } from "node:path";

const limit = Number(process.argv[2] ?? 100);
const root = process.argv[3] ?? "crate";

function files(dir) {
  return readdirSync(dir).flatMap((name) => {
    const p = join(dir, name);
    if (statSync(p).isDirectory()) return files(p);
    return p.endsWith(".rs") ? [p] : [];
  });
}

// The source with comments, strings and char literals blanked (line breaks kept).
function codeOnly(src) {
  let out = "";
  let i = 0;
  while (i < src.length) {
    const rest = src.slice(i, i + 3);
    if (rest.startsWith("//")) {
      const end = src.indexOf("\n", i);
      i = end < 0 ? src.length : end;
    } else if (rest.startsWith("/*")) {
      const end = src.indexOf("*/", i + 2);
      const stop = end < 0 ? src.length : end + 2;
      out += src.slice(i, stop).replace(/[^\n]/g, " ");
      i = stop;
    } else if (src[i] === '"' || rest.startsWith('r#"')) {
      const raw = src[i] === "r";
      let j = i + (raw ? 3 : 1);
      while (j < src.length && !(raw ? src.startsWith('"#', j) : src[j] === '"')) {
        if (!raw && src[j] === "\\") j++;
        j++;
      }
      const stop = j + (raw ? 2 : 1);
      out += src.slice(i, stop).replace(/[^\n]/g, " ");
      i = stop;
    } else if (/^'(\\.|[^\\'])'/.test(src.slice(i, i + 4))) {
      const m = src.slice(i, i + 4).match(/^'(\\.|[^\\'])'/);
      out += " ".repeat(m[0].length);
      i += m[0].length;
    } else {
      out += src[i];
      i++;
    }
  }
  return out;
}

const found = [];
for (const file of files(root)) {
  const code = codeOnly(readFileSync(file, "utf8"));
  const fnRe = /\bfn\s+([A-Za-z_][A-Za-z0-9_]*)/g;
  let m;
  while ((m = fnRe.exec(code))) {
    // The body: the first `{` after the signature, unless a `;` (a declaration) comes first.
    let k = m.index;
    let depth = 0;
    while (k < code.length && code[k] !== "{" && !(code[k] === ";" && depth === 0)) {
      if (code[k] === "(" || code[k] === "[") depth++;
      if (code[k] === ")" || code[k] === "]") depth--;
      k++;
    }
    if (code[k] !== "{") continue;
    let braces = 0;
    let end = k;
    for (; end < code.length; end++) {
      if (code[end] === "{") braces++;
      if (code[end] === "}" && --braces === 0) break;
    }
    const first = code.slice(0, m.index).split("\n").length;
    const last = code.slice(0, end).split("\n").length;
    const length = last - first + 1;
    if (length > limit) found.push({ file: relative(".", file), line: first, name: m[1], length });
  }
}
found.sort((a, b) => b.length - a.length);
for (const f of found) console.log(`${String(f.length).padStart(5)}  ${f.file}:${f.line}  ${f.name}`);
console.log(`${found.length} functions over ${limit} lines in ${root}/`);
