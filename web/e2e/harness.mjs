// What the end-to-end tests share: web/dist served on a loopback port, Debian's chromium
// driven by playwright-core, the hwfoc binary to compare with.

import { createServer } from 'node:http';
import { readFile } from 'node:fs/promises';
import { existsSync, mkdirSync, mkdtempSync, readFileSync, rmSync } from 'node:fs';
import { tmpdir } from 'node:os';
import { before, after } from 'node:test';
import { extname, join, normalize, dirname } from 'node:path';
import { fileURLToPath } from 'node:url';
import { execFileSync } from 'node:child_process';
import { chromium } from 'playwright-core';

export const WEB = dirname(dirname(fileURLToPath(import.meta.url)));
export const ROOT = dirname(WEB);
export const DIST = join(WEB, 'dist');
export const SCREENSHOTS = join(ROOT, 'target', 'web-screenshots');

const TYPES = {
  '.html': 'text/html; charset=utf-8',
  '.js': 'text/javascript; charset=utf-8',
  '.css': 'text/css; charset=utf-8',
  '.wasm': 'application/wasm',
  '.json': 'application/json',
  '.svg': 'image/svg+xml',
};

/** Serves web/dist on 127.0.0.1; resolves to {url, close}. */
export async function serve() {
  if (!existsSync(join(DIST, 'index.html'))) throw new Error(`${DIST} is not built: run web/build.sh`);
  const server = createServer(async (req, res) => {
    const path = normalize(decodeURIComponent(new URL(req.url, 'http://x').pathname)).replace(/^(\.\.[/\\])+/, '');
    const file = join(DIST, path.endsWith('/') ? `${path}index.html` : path);
    try {
      const body = await readFile(file);
      res.writeHead(200, { 'content-type': TYPES[extname(file)] ?? 'application/octet-stream' });
      res.end(body);
    } catch {
      res.writeHead(404);
      res.end('not found');
    }
  });
  await new Promise((ok) => server.listen(0, '127.0.0.1', ok));
  return { url: `http://127.0.0.1:${server.address().port}/`, close: () => server.close() };
}

/** The chromium flags of the project's headless runs. */
export const FLAGS = [
  '--headless',
  '--no-sandbox',
  '--disable-gpu',
  '--disable-quic',
  '--no-first-run',
  '--disable-background-networking',
  '--disable-component-update',
  '--disable-sync',
];

/** Debian's chromium, through playwright-core. */
export function launch() {
  const executablePath = process.env.CHROMIUM ?? '/usr/bin/chromium';
  return chromium.launch({ executablePath, args: FLAGS, headless: true });
}

/** The hwfoc binary: $HWFOC, else the workspace's debug build. */
export function hwfoc(...args) {
  const bin = process.env.HWFOC ?? join(ROOT, 'target', 'debug', 'hwfoc');
  return execFileSync(bin, args, { cwd: ROOT, maxBuffer: 1 << 28 }).toString();
}

/**
 * Why the tests of files other than raw bytes are skipped, or false: the WebAssembly build
 * reads analyser CSV, pcapng and CAN logs, and summarises, once crates/hwfoc-records (the
 * command's OS-free readers) is in the workspace; its glue then exports `openFile`.
 */
export function needsReaders() {
  const glue = readFileSync(join(DIST, 'pkg', 'hwfoc_web.js'), 'utf8');
  return /export function openFile/.test(glue)
    ? false
    : 'needs the command\'s readers in the WebAssembly build (crates/hwfoc-records)';
}

/** Makes the screenshots' folder. */
export function screenshotsDir() {
  mkdirSync(SCREENSHOTS, { recursive: true });
  return SCREENSHOTS;
}

/**
 * For a test file: web/dist served, chromium launched and a temporary folder made before its
 * tests, all three gone after. The fields of the object returned are set once `before` ran.
 * @param {string} name the temporary folder's prefix
 * @returns {{server: {url: string}, browser: import('playwright-core').Browser, dir: string}}
 */
export function useBrowser(name) {
  const context = {};
  before(async () => {
    context.server = await serve();
    context.browser = await launch();
    context.dir = mkdtempSync(join(tmpdir(), `hwfoc-web-${name}-`));
  });
  after(async () => {
    await context.browser?.close();
    context.server?.close();
    if (context.dir) rmSync(context.dir, { recursive: true, force: true });
  });
  return context;
}
