// Usage: node scripts/guard-freed.mjs GLUE.js
//
// wasm-bindgen's glue (0.2.130) hands a freed object's pointer, 0, to Rust, whose shim answers
// "null pointer passed to rust": a plain Error without `kind` and `field`, before the library's
// own checks can run (issue 21 item 1: every misuse answers the documented Error). This rewrites
// every exported class of GLUE.js so that a method, getter or second free() of an object that
// was freed, or a method called on another object, throws the documented Error instead:
// `kind: "invalid"`, `field: "this"`, "this: this RecordingParser was freed (free()); make a
// new one". Nothing else changes.
// Run by scripts/build.sh after wasm-bindgen; it fails, and the build with it, if the glue no
// longer has the shape it rewrites (a wasm-bindgen upgrade must be looked at, not shipped blind).
import { readFileSync, writeFileSync } from 'node:fs';

const file = process.argv[2];
let text = readFileSync(file, 'utf8');
const classes = [...text.matchAll(/^export class (\w+) \{$/gm)].map((m) => m[1]);
let changed = 0;
for (const name of classes) {
  const start = text.indexOf(`export class ${name} {`);
  const end = text.indexOf('\n}\n', start);
  if (end < 0) throw new Error(`${file}: the end of class ${name} not found`);
  let body = text.slice(start, end);
  const free = `    free() {\n        const ptr = this.__destroy_into_raw();\n`;
  if (!body.includes(free)) throw new Error(`${file}: ${name}.free() is not wasm-bindgen's`);
  body = body.replace(free, `    free() {\n        __live(this, ${name});\n        const ptr = this.__destroy_into_raw();\n`);
  const uses = body.split('(this.__wbg_ptr').length - 1;
  if (uses === 0) throw new Error(`${file}: no method of ${name} reads its pointer`);
  body = body.replaceAll('(this.__wbg_ptr', `(__live(this, ${name})`);
  text = text.slice(0, start) + body + text.slice(end);
  changed += uses + 1;
}
if (classes.length > 0) {
  text += `
/** The pointer of a live object of class \`cls\`; the documented Error for a freed one, or for a
 * method called on another object (scripts/guard-freed.mjs). */
function __live(object, cls) {
    if (!(object instanceof cls) || object.__wbg_ptr === 0) {
        const e = new Error(object instanceof cls
            ? \`this: this \${cls.name} was freed (free()); make a new one\`
            : \`this: must be a \${cls.name}, got another object\`);
        e.kind = 'invalid';
        e.field = 'this';
        throw e;
    }
    return object.__wbg_ptr;
}
`;
}
writeFileSync(file, text);
console.log(`[build] ${file}: ${classes.length} class(es) guarded against use after free (${changed} calls)`);
