// The service worker fetches ahead every file the page is made of, so that it opens offline.
import { test } from 'node:test';
import assert from 'node:assert/strict';
import { readFileSync, readdirSync } from 'node:fs';
import { fileURLToPath } from 'node:url';

const web = fileURLToPath(new URL('../', import.meta.url));

function filesUnder(dir) {
  return readdirSync(`${web}${dir}`, { withFileTypes: true }).flatMap((d) =>
    d.isDirectory() ? filesUnder(`${dir}/${d.name}`) : [`./${dir}/${d.name}`]);
}

test('sw.js caches ahead index.html, style.css, every file of src/ and the WebAssembly', () => {
  const sw = readFileSync(`${web}sw.js`, 'utf8');
  const ahead = new Set([...sw.match(/const AHEAD = \[([^\]]*)\]/)[1].matchAll(/'([^']+)'/g)].map((m) => m[1]));
  const want = ['./', './index.html', './style.css', './pkg/hwfoc_web.js', './pkg/hwfoc_web_bg.wasm', ...filesUnder('src')];
  assert.deepEqual(want.filter((f) => !ahead.has(f)), [], 'files the worker does not cache ahead');
  assert.deepEqual([...ahead].filter((f) => !want.includes(f)), [], 'names in AHEAD that are no file');
});

test('index.html registers the worker', () => {
  assert.match(readFileSync(`${web}index.html`, 'utf8'), /navigator\.serviceWorker\.register\('sw\.js'\)/);
});
