// Every recording in testdata/ opened in the page: its per-ESC figures equal `hwfoc summary
// --json`'s; screenshots at a phone's and a laptop's width.

import { test } from 'node:test';
import assert from 'node:assert/strict';
import { readdirSync, statSync } from 'node:fs';
import { join, relative, resolve } from 'node:path';
import { ROOT, hwfoc, needsReaders, screenshotsDir, useBrowser } from './harness.mjs';

/** The recordings of testdata/ (every file but the READMEs and the test vectors). */
function recordings() {
  const out = [];
  const walk = (dir) => {
    for (const name of readdirSync(dir).sort()) {
      const path = join(dir, name);
      if (statSync(path).isDirectory()) walk(path);
      else if (!/README|vectors/.test(name)) out.push(relative(ROOT, path));
    }
  };
  walk(join(ROOT, 'testdata'));
  return out;
}

/** The value at a dotted key. */
function at(object, key) {
  return key.split('.').reduce((o, part) => (o == null ? undefined : o[part]), object);
}

const ctx = useBrowser('files');

const skip = needsReaders();

/** Opens `files` in a fresh page of width `width`; returns the page once the summaries show. */
async function openInPage(files, width) {
  const page = await ctx.browser.newPage({ viewport: { width, height: 900 } });
  const errors = [];
  page.on('pageerror', (e) => errors.push(e.message));
  await page.goto(ctx.server.url);
  await page.waitForSelector('body[data-ready=true]');
  await page.setInputFiles('#files input[type=file]', files.map((f) => resolve(ROOT, f)));
  await page.waitForFunction(
    (n) => document.querySelectorAll('.recordings button').length === n,
    files.length,
  );
  assert.deepEqual(errors, []);
  return page;
}

for (const file of recordings()) {
  test(`${file}: the page's figures are hwfoc summary --json's`, { skip }, async () => {
    const expected = JSON.parse(hwfoc('summary', '--json', file));
    const page = await openInPage([file], 1280);
    try {
      const shown = await page.$$eval('.esc-summary', (sections) =>
        sections.map((s) => ({
          esc: Number(s.dataset.esc),
          cells: Array.from(s.querySelectorAll('[data-key]'), (c) => [c.dataset.key, c.dataset.value]),
        })),
      );
      assert.deepEqual(
        shown.map((s) => s.esc),
        expected.escs.map((e) => e.esc),
        'the ESCs',
      );
      for (const { esc, cells } of shown) {
        const want = expected.escs.find((e) => e.esc === esc);
        assert.ok(cells.length >= 10, `ESC ${esc}: figures shown`);
        for (const [key, value] of cells) {
          assert.deepEqual(JSON.parse(value), at(want, key) ?? null, `ESC ${esc} ${key}`);
        }
      }
    } finally {
      await page.close();
    }
  });
}

test('the CSV of the whole recording is hwfoc decode --format csv', { skip }, async () => {
  for (const file of ['testdata/captures/xrotor-v4-pro-hv-80A.csv', 'testdata/captures/platinum-v4.csv']) {
    const page = await openInPage([file], 1280);
    try {
      const [download] = await Promise.all([page.waitForEvent('download'), page.click('button.export')]);
      const csv = await (await download.createReadStream()).toArray();
      const shown = Buffer.concat(csv).toString();
      const expected = hwfoc('decode', '--format', 'csv', file);
      const a = shown.split('\n');
      const b = expected.split('\n');
      for (let i = 0; i < Math.max(a.length, b.length); i++) {
        assert.equal(a[i], b[i], `${file}: line ${i + 1}`);
      }
    } finally {
      await page.close();
    }
  }
});

test('screenshots at 390 px and 1280 px', async () => {
  const shots = screenshotsDir();
  // A minute of a virtual ESC's raw bytes (with a fault episode: --demo's run), and, where the
  // page reads them, a capture and a CAN bus.
  const sim = join(ctx.dir, 'sim.bin');
  hwfoc('simulate', '--duration', '60', '-o', sim);
  const files = skip ? [] : ['testdata/captures/xrotor-v4-pro-hv-80A.csv', 'testdata/dronecan/can-bus.candump.txt'];
  files.push(sim);
  for (const width of [390, 1280]) {
    const page = await openInPage(files, width);
    try {
      await page.waitForSelector('canvas.chart');
      await page.waitForTimeout(100);
      const canvas = page.locator('canvas.chart').first();
      await canvas.scrollIntoViewIfNeeded();
      const box = await canvas.boundingBox();
      await page.mouse.move(box.x + box.width / 2, box.y + box.height / 2);
      await page.waitForTimeout(50);
      const readout = await page.textContent('.readout');
      assert.match(readout, /ESC \d+: /, 'the cursor readout');
      await page.evaluate(() => window.scrollTo(0, 0));
      await page.screenshot({ path: join(shots, `files-${width}.png`), fullPage: true });
      // Every column of each ESC's summary can be brought onto the screen (issue 34).
      const heads = page.locator('.esc-summary table.fields tr:first-child th');
      assert.ok(await heads.count() >= 5);
      for (let i = 0; i < await heads.count(); i++) {
        const th = heads.nth(i);
        await th.scrollIntoViewIfNeeded();
        const box = await th.boundingBox();
        assert.ok(box && box.x >= 0 && box.x + box.width <= width, `${await th.textContent()}: ${JSON.stringify(box)}`);
      }
      await page.evaluate(() => window.scrollTo(0, 0));
      // The readout names the shown recording's range (the last file's: frames), also after a
      // resize, when the tabs shown before once drew theirs into it.
      // (The shown plot's redraw is queued first, by the pointer leaving, as a screenshot's
      // resize found it after the cursor readout.)
      await page.mouse.move(0, 0);
      await page.evaluate(() => {
        document.querySelector('canvas.chart').dispatchEvent(new Event('pointerleave'));
        window.dispatchEvent(new Event('resize'));
      });
      await page.waitForTimeout(100);
      assert.match(await page.textContent('.readout'), / frame$/, 'the range of the recording shown');
      const overflow = await page.evaluate(() => document.documentElement.scrollWidth - window.innerWidth);
      assert.ok(overflow <= 0, `no sideways scrolling at ${width} px (${overflow} px too wide)`);
    } finally {
      await page.close();
    }
  }
});
