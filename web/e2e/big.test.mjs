// The budget: a 2-hour recording of 8 ESCs (the simulator's, about 1.15 million frames)
// opens, summarised and charted, in under 3 s, and a zoom redraws every chart in well under a
// second. Measured 1.5 s with the machine's two cores shared (load 4 to 5; 3.5 s at load 6 to
// 10 before the quantities were found by a plain loop), so the test fails only past twice the
// budget (a regression), and prints the time.

import { test } from 'node:test';
import assert from 'node:assert/strict';
import { join } from 'node:path';
import { hwfoc, needsReaders, useBrowser } from './harness.mjs';

const ctx = useBrowser('big');

/** Waits for the page to have drawn (two animation frames). */
const drawn = (page) =>
  page.evaluate(() => new Promise((r) => requestAnimationFrame(() => requestAnimationFrame(r))));

test('a 2-hour recording of 8 ESCs opens in about 3 s', { skip: needsReaders() }, async () => {
  const file = join(ctx.dir, 'two-hours.pcapng');
  // 8 ESCs for 9000 s at the simulator's 16 frames a second: 1.15 million data frames, as many
  // as 2 hours at 20 frames a second.
  hwfoc('simulate', '--escs', '8', '--duration', '9000', '-o', file);
  const page = await ctx.browser.newPage({ viewport: { width: 1280, height: 900 } });
  try {
    await page.goto(ctx.server.url);
    await page.waitForSelector('body[data-ready=true]');
    const started = Date.now();
    await page.setInputFiles('#files input[type=file]', file);
    await page.waitForSelector('canvas.chart');
    await drawn(page);
    const openMs = Date.now() - started;
    const frames = await page.$$eval('[data-key=frames]', (cells) =>
      cells.reduce((n, c) => n + JSON.parse(c.dataset.value), 0),
    );
    console.log(`# ${frames} frames of 8 ESCs opened and drawn in ${openMs} ms`);
    assert.ok(frames > 1_100_000, `${frames} frames`);
    assert.equal(await page.locator('.esc-summary').count(), 8);
    assert.ok(openMs < 6000, `opened in ${openMs} ms (the budget: 3000)`);

    const box = await page.locator('canvas.chart').first().boundingBox();
    await page.mouse.move(box.x + box.width / 2, box.y + box.height / 2);
    const zoomStarted = Date.now();
    await page.mouse.wheel(0, -100);
    await drawn(page);
    const zoomMs = Date.now() - zoomStarted;
    console.log(`# a zoom redrew every chart in ${zoomMs} ms`);
    assert.ok(zoomMs < 500, `a zoom took ${zoomMs} ms`);
  } finally {
    await page.close();
  }
});
