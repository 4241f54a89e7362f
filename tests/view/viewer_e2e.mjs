// SPDX-License-Identifier: MIT
// Copyright (c) 2026 the pointform authors
//
// The browser test of `pointform view` (CTest viewer_e2e, through run_viewer_e2e.sh): starts the
// server on a hierarchy, drives Debian's chromium headless through playwright-core (installed in
// viewer/node_modules by scripts/setup.sh; no browser download; WebGL through SwiftShader) and
// checks that every level arrives, the canvas is not blank, each level has 4 times the faces of
// the one below, the picture export gives a PNG, and nothing but the page and the data is served.
//   node viewer_e2e.mjs POINTFORM HIERARCHY.pfh OUTPUT_FOLDER [DOCS_SCREENSHOT.png]
// Exits 0 on success, 1 on a failed check, 77 (skipped) without chromium or playwright-core.

import { spawn, execFileSync } from 'node:child_process';
import { existsSync, mkdirSync, readFileSync, copyFileSync } from 'node:fs';
import { createRequire } from 'node:module';
import http from 'node:http';
import path from 'node:path';
import { fileURLToPath } from 'node:url';

const here = path.dirname(fileURLToPath(import.meta.url));
const viewerDir = path.resolve(here, '../../viewer');
const chromiumPath = process.env.PF_CHROMIUM ?? '/usr/bin/chromium';

const [cli, hierarchy, outDir, docsScreenshot] = process.argv.slice(2);
if (!cli || !hierarchy || !outDir) {
  console.error('usage: node viewer_e2e.mjs POINTFORM HIERARCHY.pfh OUTPUT_FOLDER [DOCS_SCREENSHOT.png]');
  process.exit(2);
}
if (!existsSync(chromiumPath)) {
  console.log(`skipped: ${chromiumPath} not found; bash scripts/setup.sh installs chromium`);
  process.exit(77);
}
let chromium;
try {
  ({ chromium } = createRequire(path.join(viewerDir, 'package.json'))('playwright-core'));
} catch (error) {
  console.log(`skipped: playwright-core is not installed in ${viewerDir}/node_modules (${error.code ?? error}); ` +
    'bash scripts/setup.sh runs npm ci there');
  process.exit(77);
}

let failures = 0;
function check(condition, what) {
  console.log(`${condition ? 'ok  ' : 'FAIL'} ${what}`);
  if (!condition) failures += 1;
}

/** Starts `pointform view FILE --port 0` and resolves to { server, url } once it prints the URL. */
function startServer(file) {
  return new Promise((resolve, reject) => {
    const server = spawn(cli, ['view', file, '--port', '0'], { stdio: ['ignore', 'pipe', 'pipe'] });
    let out = '';
    const timer = setTimeout(() => reject(new Error(`no URL printed within 20 s: ${out}`)), 20000);
    server.stdout.on('data', (chunk) => {
      out += chunk;
      const match = out.match(/http:\/\/127\.0\.0\.1:(\d+)\//);
      if (match) {
        clearTimeout(timer);
        resolve({ server, url: match[0], port: Number(match[1]) });
      }
    });
    server.stderr.on('data', (chunk) => process.stderr.write(chunk));
    server.on('exit', (code) => reject(new Error(`pointform view exited with ${code} before serving: ${out}`)));
  });
}

/** GET with a raw path (no normalisation of "..", which browsers and fetch() would do). */
function rawGet(port, rawPath) {
  return new Promise((resolve, reject) => {
    const request = http.request({ host: '127.0.0.1', port, path: rawPath, method: 'GET' }, (response) => {
      response.resume();
      response.on('end', () => resolve(response.statusCode));
    });
    request.on('error', reject);
    request.end();
  });
}

const expected = JSON.parse(execFileSync(cli, ['lod', hierarchy, '--json'], { encoding: 'utf8' })).levels;
mkdirSync(outDir, { recursive: true });
const { server, url, port } = await startServer(hierarchy);
const serverExit = new Promise((resolve) => server.on('exit', (code, signal) => resolve({ code, signal })));
const browser = await chromium.launch({
  executablePath: chromiumPath,
  headless: true,
  args: ['--no-sandbox', '--use-angle=swiftshader', '--enable-unsafe-swiftshader',
    '--disable-background-networking', '--disable-component-update', '--no-first-run'],
  timeout: 30000,
});
try {
  const page = await browser.newPage({ viewport: { width: 960, height: 640 }, acceptDownloads: true });
  const errors = [];
  page.on('pageerror', (error) => errors.push(String(error)));
  page.on('console', (message) => { if (message.type() === 'error') errors.push(message.text()); });
  await page.goto(url);
  const levelCount = await page.evaluate(() => window.pointform.ready());
  check(errors.length === 0, `no errors on the page ${errors.length ? JSON.stringify(errors) : ''}`);
  check(levelCount === expected.length,
    `levelCount() ${await page.evaluate(() => window.pointform.levelCount())} = ${expected.length} levels of pointform lod`);
  check(await page.evaluate(() => window.pointform.level()) === expected.length - 1,
    'the finest level is shown once every level has arrived');

  // Level by level: the faces drawn are the hierarchy's, 4 times those of the level below.
  for (let i = 0; i + 1 < expected.length; ++i) {
    const coarse = await page.evaluate((l) => { window.pointform.setLevel(l); return window.pointform.faceCount(); }, i);
    const fine = await page.evaluate((l) => { window.pointform.setLevel(l); return window.pointform.faceCount(); }, i + 1);
    check(coarse === expected[i].faces && fine === 4 * coarse,
      `setLevel(${i}) -> ${coarse} faces, setLevel(${i + 1}) -> ${fine} = 4 x ${coarse}`);
  }
  check(await page.evaluate(() => { try { window.pointform.setLevel(99); return false; } catch { return true; } }),
    'setLevel(99) throws');

  // Not blank: the canvas's pixels vary (a uniform clear colour has variance 0).
  const pixels = await page.evaluate(() => {
    const source = document.getElementById('view');
    const copy = document.createElement('canvas');
    copy.width = source.width;
    copy.height = source.height;
    const context = copy.getContext('2d');
    context.drawImage(source, 0, 0);
    const data = context.getImageData(0, 0, copy.width, copy.height).data;
    let sum = 0, sum2 = 0, differing = 0;
    const n = data.length / 4;
    for (let k = 0; k < data.length; k += 4) {
      const y = 0.299 * data[k] + 0.587 * data[k + 1] + 0.114 * data[k + 2];
      sum += y;
      sum2 += y * y;
      if (Math.abs(data[k] - data[0]) + Math.abs(data[k + 1] - data[1]) + Math.abs(data[k + 2] - data[2]) > 30) differing += 1;
    }
    const mean = sum / n;
    return { variance: sum2 / n - mean * mean, covered: differing / n };
  });
  check(pixels.variance > 100 && pixels.covered > 0.02,
    `the canvas is not blank (luminance variance ${pixels.variance.toFixed(1)}, ${(100 * pixels.covered).toFixed(1)}% of the pixels drawn)`);

  // Wireframe draws the same triangles; the base mesh overlay adds lines.
  await page.evaluate(() => window.pointform.setWireframe(true));
  check(await page.evaluate(() => window.pointform.faceCount()) === expected[expected.length - 1].faces,
    'wireframe on: faceCount() unchanged');
  await page.evaluate(() => window.pointform.setWireframe(false));

  // The picture export downloads a PNG.
  const [download] = await Promise.all([page.waitForEvent('download'), page.click('#export')]);
  const exported = path.join(outDir, download.suggestedFilename());
  await download.saveAs(exported);
  const magic = readFileSync(exported).subarray(0, 8).toString('hex');
  check(magic === '89504e470d0a1a0a' && exported.endsWith('.png'), `save picture -> ${exported} is a PNG`);

  // Only the page and the data of the file named on the command line are served.
  const refused = await page.evaluate(async () => {
    const paths = ['/bunny.pfh', '/data/bunny/bun_zipper.ply', '/CMakeLists.txt', '/web/index.html',
      '/node_modules/three/package.json', '/api/level/99', '/api/points', '/etc/passwd'];
    const statuses = {};
    for (const p of paths) statuses[p] = (await fetch(p)).status;
    statuses['POST /api/info'] = (await fetch('/api/info', { method: 'POST', body: 'x' })).status;
    return statuses;
  });
  for (const rawPath of ['/../../etc/passwd', '/vendor/../../CMakeLists.txt', '/%2e%2e/%2e%2e/etc/passwd']) {
    refused[`raw ${rawPath}`] = await rawGet(port, rawPath);
  }
  for (const [what, status] of Object.entries(refused)) {
    check(status >= 400 && status < 500, `${what} refused with ${status}`);
  }
  check(await page.evaluate(async () => (await fetch('/api/info')).status) === 200,
    'the server still answers after the refused requests');

  // The screenshot: the finest level with the base mesh over it.
  await page.evaluate((l) => { window.pointform.setLevel(l); window.pointform.setBaseOverlay(true); }, expected.length - 1);
  const shot = path.join(outDir, 'viewer_bunny.png');
  await page.screenshot({ path: shot });
  console.log(`screenshot: ${shot}`);
  if (docsScreenshot) {
    copyFileSync(shot, docsScreenshot);
    console.log(`screenshot copied to ${docsScreenshot}`);
  }
} finally {
  await browser.close();
  server.kill('SIGINT');
}
const { code, signal } = await serverExit;
check(code === 0 && signal === null, `pointform view stops on SIGINT with exit 0 (exit ${code}, signal ${signal})`);
console.log(failures === 0 ? 'viewer_e2e: all checks passed' : `viewer_e2e: ${failures} checks failed`);
process.exit(failures === 0 ? 0 : 1);
