// scripts/stamp.sh, what scripts/build.sh keeps or rebuilds a module by (issue 21, item 6): the
// stamp changes when a source's content changes, a file is added or deleted, or a build word
// (features, toolchain) or RUSTFLAGS changes, and does not change on `touch` or a re-run. Run on
// a copy of crate/ in a scratch directory; then build.sh --check on the built pkg/: every
// module's stamp matches its inputs as computed anew, and a different RUSTFLAGS makes them stale.
import { test } from 'node:test';
import assert from 'node:assert/strict';
import { execFileSync } from 'node:child_process';
import { appendFileSync, cpSync, mkdirSync, mkdtempSync, rmSync, utimesSync, writeFileSync, unlinkSync } from 'node:fs';
import { tmpdir } from 'node:os';
import { join } from 'node:path';
import { fileURLToPath } from 'node:url';

const root = fileURLToPath(new URL('../../', import.meta.url));

test('the stamp follows the contents of the inputs, not their times', () => {
  const dir = mkdtempSync(join(tmpdir(), 'input-shaping-stamp-'));
  try {
    for (const p of ['crate', 'Cargo.toml', 'Cargo.lock']) cpSync(join(root, p), join(dir, p), { recursive: true });
    mkdirSync(join(dir, 'scripts'));
    cpSync(join(root, 'scripts/stamp.sh'), join(dir, 'scripts/stamp.sh'));
    const stamp = (words = ['features=js-api'], env = {}) => execFileSync('bash',
      ['scripts/stamp.sh', '--files', 'crate', 'Cargo.toml', 'Cargo.lock', 'absent.toml', '--', ...words],
      { cwd: dir, encoding: 'utf8', env: { ...process.env, RUSTFLAGS: '', ...env } }).trim();
    const first = stamp();
    assert.match(first, /^[0-9a-f]{64}$/);
    assert.equal(stamp(), first, 'a re-run gives the same stamp');
    utimesSync(join(dir, 'crate/lib.rs'), new Date(), new Date(Date.now() + 60_000));
    assert.equal(stamp(), first, 'touch alone keeps it');
    assert.notEqual(stamp(['features=js-recording']), first, 'other features');
    assert.notEqual(stamp(['features=js-api', 'rustc 1.2.3']), first, 'another word (toolchain)');
    assert.notEqual(stamp(undefined, { RUSTFLAGS: '-C debug-assertions' }), first, 'RUSTFLAGS');
    appendFileSync(join(dir, 'crate/mode.rs'), '\n// an edit\n');
    const edited = stamp();
    assert.notEqual(edited, first, 'an edited source');
    writeFileSync(join(dir, 'crate/new.rs'), '');
    const added = stamp();
    assert.notEqual(added, edited, 'an added (even empty) file');
    unlinkSync(join(dir, 'crate/new.rs'));
    assert.equal(stamp(), edited, 'deleting it again gives back the stamp before');
    writeFileSync(join(dir, 'absent.toml'), '');
    assert.notEqual(stamp(), edited, 'a missing input that appears');
  } finally {
    rmSync(dir, { recursive: true, force: true });
  }
});

test('build.sh --check: the built modules are up to date, and stale under other RUSTFLAGS', () => {
  const check = (env = {}) => {
    try {
      return { code: 0, out: execFileSync('bash', ['scripts/build.sh', '--check'], { cwd: root, encoding: 'utf8', env: { ...process.env, ...env } }) };
    } catch (e) {
      return { code: e.status, out: `${e.stdout}${e.stderr}` };
    }
  };
  const now = check();
  assert.equal(now.code, 0, now.out);
  // The library and the page's four modules (playground, designer, recording, corner).
  const MODULES = 5;
  assert.equal(now.out.match(/up to date/g)?.length, MODULES, now.out);
  const other = check({ RUSTFLAGS: `${process.env.RUSTFLAGS ?? ''} -C debug-assertions=off` });
  assert.equal(other.code, 1, other.out);
  assert.equal(other.out.match(/to be rebuilt/g)?.length, MODULES, other.out);
});
