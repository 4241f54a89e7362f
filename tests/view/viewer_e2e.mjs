// SPDX-License-Identifier: MIT
// Copyright (c) 2026 the pointform authors
//
// The browser test of `pointform view` (CTest viewer_e2e, through run_viewer_e2e.sh): starts the
// server on a hierarchy and its samples, drives Debian's chromium headless through playwright-core
// (installed in viewer/node_modules by scripts/setup.sh; no browser download; WebGL through
// SwiftShader) and checks that every level arrives, the canvas is not blank, each level has 4
// times the faces of the one below, the distances to the samples agree with the reconstruction's
// report, the picture export gives a PNG, a base mesh picked by mouse clicks is checked live,
// refused when it is not a manifold, reconstructed on the server with the same result as
// `pointform reconstruct --base-mesh` with the saved OBJ, and nothing but the page and the data
// is served.
//   node viewer_e2e.mjs POINTFORM HIERARCHY.pfh SAMPLES REPORT.json OUTPUT_FOLDER [DOCS_SCREENSHOT.png]
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

const [cli, hierarchy, samplesFile, reportFile, outDir, docsScreenshot] = process.argv.slice(2);
if (!cli || !hierarchy || !samplesFile || !reportFile || !outDir) {
  console.error('usage: node viewer_e2e.mjs POINTFORM HIERARCHY.pfh SAMPLES REPORT.json OUTPUT_FOLDER [DOCS_SCREENSHOT.png]');
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

/** Starts `pointform view FILES --port 0` and resolves to { server, url } once it prints the URL. */
function startServer(files) {
  return new Promise((resolve, reject) => {
    const server = spawn(cli, ['view', ...files, '--port', '0'], { stdio: ['ignore', 'pipe', 'pipe'] });
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

const lod = (file) => JSON.parse(execFileSync(cli, ['lod', file, '--json'], { encoding: 'utf8' })).levels;
const expected = lod(hierarchy);
const near = (a, b, tolerance) => Math.abs(a - b) <= tolerance * Math.max(Math.abs(a), Math.abs(b));
mkdirSync(outDir, { recursive: true });
const report = JSON.parse(readFileSync(reportFile, 'utf8'));
const { server, url, port } = await startServer([hierarchy, samplesFile]);
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
  // Actions wait for the page to draw stable frames; software WebGL next to the rest of the
  // suite on two cores has taken over 30 s (Playwright's default) for one click.
  page.setDefaultTimeout(120000);
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
    const paths = ['/bunny.pfh', '/samples.ply', '/data/bunny/bun_zipper.ply', '/CMakeLists.txt',
      '/web/index.html', '/node_modules/three/package.json', '/api/layer/0/level/99',
      '/api/layer/0/points', '/api/layer/7/points', '/api/layer/1/level/0', '/api/layer/x/points',
      '/api/layer/0/distance/99', '/etc/passwd'];
    const statuses = {};
    for (const p of paths) statuses[p] = (await fetch(p)).status;
    statuses['POST /api/info'] = (await fetch('/api/info', { method: 'POST', body: 'x' })).status;
    for (const body of ['x', '[[[[[[[[[[', '{"triangles": [[0, 1]]}', '{"triangles": [[0, 1, 99999999]]}',
      '{"triangles": []}', '{"triangles": [[0, 1, -2]]}']) {
      statuses[`POST /api/reconstruct ${body}`] = (await fetch('/api/reconstruct', { method: 'POST', body })).status;
    }
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
  errors.length = 0; // the refused requests above were logged by the browser as failed loads

  // Colour by distance: the server's distances from the samples to each level are the
  // reconstruction report's one-sided Hausdorff distances.
  await page.evaluate(() => window.pointform.setColorByDistance(true));
  for (let i = 0; i < expected.length; ++i) {
    const measured = await page.evaluate((l) => window.pointform.hausdorff(l), i);
    const reported = report.levels[i].hausdorff;
    check(near(measured, reported, 1e-5),
      `level ${i}: Hausdorff from the samples ${measured.toPrecision(6)} = the report's ${reported.toPrecision(6)}`);
  }
  check(await page.evaluate(() => document.getElementById('legend').textContent.startsWith('distance')),
    'colour by distance shows its legend');
  await page.evaluate(() => window.pointform.setColorByDistance(false));

  // The picture export downloads a PNG (above); the screenshot: the finest level with the base
  // mesh over it, before any picking.
  await page.evaluate((l) => {
    window.pointform.setLayerVisible(1, false); // the samples
    window.pointform.setLevel(l);
    window.pointform.setBaseOverlay(true);
  }, expected.length - 1);
  const shot = path.join(outDir, 'viewer_bunny.png');
  await page.screenshot({ path: shot });
  console.log(`screenshot: ${shot}`);
  if (docsScreenshot) {
    copyFileSync(shot, docsScreenshot);
    console.log(`screenshot copied to ${docsScreenshot}`);
  }
  await page.evaluate(() => { window.pointform.setBaseOverlay(false); window.pointform.setLayerVisible(1, true); });

  // The interactive base mesh (Fig. 6), by mouse clicks: an octahedron over the samples
  // farthest along the six axes, each picked in the view from its axis.
  await page.check('#pick-mode');
  const box = await page.locator('#view').boundingBox();
  const axes = [[1, 0, 0], [-1, 0, 0], [0, 1, 0], [0, -1, 0], [0, 0, 1], [0, 0, -1]];
  const octahedron = [[0, 2, 4], [2, 1, 4], [1, 3, 4], [3, 0, 4], [2, 0, 5], [1, 2, 5], [3, 1, 5], [0, 3, 5]];
  const vertexOf = new Map(); // axis -> picked sample
  const click = async (x, y) => {
    await page.mouse.click(box.x + x, box.y + y);
  };
  for (const face of octahedron) {
    for (const a of face) {
      // Each vertex is clicked in the view from its axis, where it is in front.
      await page.evaluate((d) => window.pointform.setView(d), axes[a]);
      if (vertexOf.has(a)) {
        const [x, y] = await page.evaluate((s) => window.pointform.sampleScreenPosition(s), vertexOf.get(a));
        await click(x, y);
        continue;
      }
      // The centre of the view, or the nearest point around it where a sample is drawn.
      const target = await page.evaluate(() => {
        const [cx, cy] = window.pointform.sceneCentreOnScreen();
        for (let r = 0; r < 200; r += 4) {
          for (let k = 0; k < Math.max(1, 2 * r); ++k) {
            const x = cx + r * Math.cos(k * Math.PI / Math.max(1, r));
            const y = cy + r * Math.sin(k * Math.PI / Math.max(1, r));
            if (window.pointform.pickSample(x, y) !== null) return [x, y];
          }
        }
        return null;
      });
      check(target !== null, `a sample is drawn near the centre of the view from ${axes[a]}`);
      const before = (await page.evaluate(() => window.pointform.baseMesh())).vertices.length;
      await click(...target);
      const after = await page.evaluate(() => window.pointform.baseMesh());
      vertexOf.set(a, after.vertices[after.vertices.length - 1]);
      check(after.vertices.length === before + 1, `a click from ${axes[a]} picks sample ${vertexOf.get(a)}`);
    }
  }
  let picked = await page.evaluate(() => window.pointform.baseMesh());
  check(picked.triangles.length === 8 && picked.check.closed && picked.check.manifold && picked.check.orientable &&
    picked.check.euler === 2 && picked.check.ok,
    `8 triangles by clicks: closed, manifold, oriented, Euler characteristic ${picked.check.euler} (${picked.shownChecks.join('; ')})`);
  // Undo takes the last triangle back (an open mesh, one boundary loop of 3 edges) ...
  await page.click('#undo');
  picked = await page.evaluate(() => window.pointform.baseMesh());
  check(picked.triangles.length === 7 && picked.check.boundaryEdges === 3 && picked.check.ok,
    `undo: 7 triangles, 3 boundary edges (${picked.check.boundaryEdges} shown)`);
  const last = octahedron[7].map((a) => vertexOf.get(a));
  await page.evaluate((t) => window.pointform.joinTriangle(...t), last);
  // ... and a fin on an edge is not a manifold: shown on the page, refused by the server.
  const fin = await page.evaluate(() => {
    const p = window.pointform;
    const extra = [0, 1, 2, 3, 4, 5].map((k) => 100 + 997 * k).find((s) => !p.baseMesh().vertices.includes(s));
    p.addVertex(extra);
    const [a, b] = p.baseMesh().triangles[0];
    p.joinTriangle(a, b, extra);
    return { extra, state: p.baseMesh(), disabled: document.getElementById('reconstruct').disabled };
  });
  check(!fin.state.check.manifold && fin.disabled &&
    fin.state.shownChecks.some((t) => t.startsWith('not a manifold: the edge between samples')),
    `a third triangle on an edge: "${fin.state.shownChecks.find((t) => t.startsWith('not a manifold')) ?? ''}", reconstruct disabled`);
  const refusal = await page.evaluate(() => window.pointform.reconstruct(true));
  const shownRefusal = await page.evaluate(() => window.pointform.jobText());
  check(refusal.state === 'failed' && /more than two triangles/.test(refusal.message) && shownRefusal.startsWith('refused:'),
    `the server refuses it with the reason on the page: "${shownRefusal}"`);
  await page.evaluate(() => { window.pointform.undo(); window.pointform.undo(); });
  picked = await page.evaluate(() => window.pointform.baseMesh());
  check(picked.check.ok && picked.triangles.length === 8 && picked.vertices.length === 6,
    'undo twice: the octahedron again');

  // Save it in the format --base-mesh reads.
  const [saved] = await Promise.all([page.waitForEvent('download'), page.click('#save-base')]);
  const savedObj = path.join(outDir, saved.suggestedFilename());
  await saved.saveAs(savedObj);
  check(savedObj.endsWith('.obj') && /^v /m.test(readFileSync(savedObj, 'utf8')), `save base mesh -> ${savedObj}`);

  // Reconstruct on the server: the new levels arrive as a layer, 4x the faces per level. Under
  // the sanitizers the reconstruction takes about 30 s alone, and more than 120 s on a machine
  // busy with something else (a CI run beside a benchmark); the ctest timeout is 600 s.
  await page.click('#reconstruct');
  await page.waitForFunction(() => window.pointform.layers().some((l) => l.source === 'reconstruction') &&
    window.pointform.loadedLevels() === window.pointform.levelCount(), null, { timeout: 400000 });
  const rebuilt = await page.evaluate(() => {
    const p = window.pointform;
    const faces = [];
    for (let i = 0; i < p.levelCount(); ++i) { p.setLevel(i); faces.push(p.faceCount()); }
    return { faces, report: p.report(), text: p.jobText() };
  });
  check(rebuilt.faces.length > 1 && rebuilt.faces.every((f, i) => f === 8 * 4 ** i),
    `Reconstruct returned ${rebuilt.faces.length} levels of ${rebuilt.faces.join(', ')} faces (${rebuilt.text})`);

  // The second picture: the picked octahedron over the samples and the level 2 it gave.
  await page.evaluate(() => {
    const p = window.pointform;
    p.setLayerVisible(1, false); // the samples: the picked octahedron stays drawn
    p.setLevel(3);
    p.setView([0.6, 0.35, 1]);
  });
  const pickedShot = path.join(outDir, 'viewer_picked.png');
  await page.screenshot({ path: pickedShot });
  console.log(`screenshot: ${pickedShot}`);
  if (docsScreenshot) {
    const docsPicked = path.join(path.dirname(docsScreenshot), 'viewer_picked.png');
    copyFileSync(pickedShot, docsPicked);
    console.log(`screenshot copied to ${docsPicked}`);
  }
  await page.evaluate(() => window.pointform.setLayerVisible(1, true));

  // The same library call as the command line with the saved base mesh: same levels and figures.
  const cliReport = JSON.parse(execFileSync(cli, ['reconstruct', samplesFile, '--base-mesh', savedObj,
    '-o', path.join(outDir, 'picked.ply'), '--save-hierarchy', path.join(outDir, 'picked.pfh'), '--json'],
  { encoding: 'utf8' }));
  const same = cliReport.levels.length === rebuilt.report.levels.length &&
    cliReport.levels.every((l, i) => near(l.hausdorff, rebuilt.report.levels[i].hausdorff, 1e-12));
  check(same, `pointform reconstruct --base-mesh ${path.basename(savedObj)}: ${cliReport.levels.length} levels, ` +
    `the same Hausdorff distances as the page's reconstruction (finest ${cliReport.levels.at(-1).hausdorff.toPrecision(6)})`);
  check(errors.length === 0, `no errors on the page after picking ${errors.length ? JSON.stringify(errors) : ''}`);
} finally {
  await browser.close();
  server.kill('SIGINT');
}
const { code, signal } = await serverExit;
check(code === 0 && signal === null, `pointform view stops on SIGINT with exit 0 (exit ${code}, signal ${signal})`);
console.log(failures === 0 ? 'viewer_e2e: all checks passed' : `viewer_e2e: ${failures} checks failed`);
process.exit(failures === 0 ? 0 : 1);
