// `elastic studio`'s server without a browser: it serves only its own files and the page's
// requests, gives bad input the CLI's messages and keeps serving, survives 100 concurrent requests
// and clients that hang up mid-stream, and a run's saved job repeats with the CLI to the same
// report numbers.
import assert from 'node:assert/strict';
import fs from 'node:fs';
import path from 'node:path';
import { after, before, test } from 'node:test';
import http from 'node:http';

import { api, cli, out, rawRequest, request, shared, startStudio, waitForRun } from './common.mjs';

const source = path.join(shared, 'meshes/grid.off');
const target = path.join(shared, 'meshes/hemisphere.off');
let studio;

before(async () => {
  fs.mkdirSync(out, { recursive: true });
  studio = await startStudio(['--source', source, '--target', target, '--work-dir', out]);
});
after(() => studio.process.kill('SIGTERM'));

test('serves the page and three.js from the build, nothing outside it', async () => {
  const page = await request(studio.port, '/');
  assert.equal(page.status, 200);
  assert.match(page.body, /ElasticPaint studio/);
  const three = await request(studio.port, '/three/three.module.js');
  assert.equal(three.status, 200);
  assert.match(three.headers['content-type'], /javascript/);
  for (const p of ['/../CMakeLists.txt', '/%2e%2e/%2e%2e/CMakeLists.txt', '/../../../../etc/passwd',
    '/three/../../studio_server.cpp']) {
    const raw = await rawRequest(studio.port,
      `GET ${p} HTTP/1.1\r\nHost: 127.0.0.1:${studio.port}\r\nConnection: close\r\n\r\n`);
    const status = Number(raw.split(' ')[1]);
    assert.ok(status >= 400, `${p} answered ${status}`);
    assert.doesNotMatch(raw, /root:|cmake_minimum_required|#include/);
  }
  // The page may load only files under the roots (the start meshes' folders, the working folder).
  const outside = await api(studio.port, '/api/load', { side: 'source', path: '/etc/passwd' });
  assert.equal(outside.status, 400);
  assert.match(outside.json.error, /outside the folders the studio serves/);
  const image = await request(studio.port, `/api/file?path=${encodeURIComponent('/etc/passwd')}`);
  assert.equal(image.status, 400);
});

test('refuses other hosts and origins', async () => {
  const origin = await request(studio.port, '/api/state', { headers: { Origin: 'http://evil.example' } });
  assert.equal(origin.status, 403);
  assert.match(JSON.parse(origin.body).error, /another host or origin/);
  const host = await request(studio.port, '/api/state', { headers: { Host: `evil.example:${studio.port}` } });
  assert.equal(host.status, 403);
  const post = await request(studio.port, '/api/map', {
    method: 'POST', headers: { Origin: 'http://localhost:1' }, body: { particles: 100 },
  });
  assert.equal(post.status, 403);
  const same = await request(studio.port, '/api/state',
    { headers: { Origin: `http://127.0.0.1:${studio.port}` } });
  assert.equal(same.status, 200);
});

test('bad input gets the message the CLI prints, and the server keeps serving', async () => {
  // A disk centred far off the surface.
  const spec = 'disk:5,5,5,0.2';
  const page = await api(studio.port, '/api/region', { side: 'source', spec });
  assert.equal(page.status, 422);
  const run = cli(['map', '--source', source, '--source-region', spec, '--target', target,
    '--particles', '100', '--quiet']);
  assert.equal(run.status, 65);
  assert.equal(page.json.error, run.stderr.trim());
  // A missing mesh.
  const missing = path.join(out, 'missing.obj');
  const load = await api(studio.port, '/api/load', { side: 'target', path: missing });
  assert.equal(load.status, 404);
  const info = cli(['info', missing]);
  assert.equal(info.status, 66);
  assert.equal(load.json.error, info.stderr.trim());
  // A malformed job key, as `elastic map --job` says it.
  const job = await api(studio.port, '/api/map', { particles: 100, 'no-such-flag': 1 });
  assert.equal(job.status, 400);
  assert.match(job.json.error, /^elastic: .*no-such-flag/);
  // Not JSON, a wrong side.
  const notJson = await request(studio.port, '/api/snap', { method: 'POST', body: undefined });
  assert.equal(notJson.status, 400);
  const side = await api(studio.port, '/api/snap', { side: 'middle', point: [0, 0, 0] });
  assert.equal(side.status, 400);
  assert.match(side.json.error, /side: expected 'source' or 'target'/);
  const state = await api(studio.port, '/api/state');
  assert.equal(state.status, 200);
});

// Bursts of 100 connections at once: a listen backlog too small for them (cpp-httplib's 5) drops
// handshakes, which clients retry for up to two minutes; the time limit catches that hang.
test('a drawn polygon becomes a points: region; an image loads as the source plane', async () => {
  const ring = [];
  for (let k = 0; k < 6; ++k) {
    const a = (2 * Math.PI * k) / 6, r = 0.4;
    ring.push([r * Math.cos(a), r * Math.sin(a), Math.sqrt(1 - r * r)]);
  }
  const polygon = await api(studio.port, '/api/region', { side: 'target', points: ring });
  assert.equal(polygon.status, 200, JSON.stringify(polygon.json));
  assert.match(polygon.json.spec, /^points:.*target-points-\d+\.txt$/);
  const file = polygon.json.spec.slice('points:'.length);
  assert.equal(fs.readFileSync(file, 'utf8').trim().split('\n').length, 6);
  // The CLI cuts the same region from the file the studio wrote.
  const region = cli(['region', target, polygon.json.spec, '--json']);
  assert.equal(region.status, 0, region.stderr);
  const area = JSON.parse(region.stdout).area;
  assert.ok(Math.abs(area - polygon.json.area) <= 1e-9 * area, `${area} vs ${polygon.json.area}`);
  const tooFew = await api(studio.port, '/api/region', { side: 'target', points: [[0, 0, 1], [0, 1, 0]] });
  assert.ok(tooFew.status >= 400, JSON.stringify(tooFew.json));
  const image = await api(studio.port, '/api/load',
    { side: 'source', path: path.join(shared, 'meshes/pmp_logo_512.png') });
  assert.equal(image.status, 200, JSON.stringify(image.json));
  assert.equal(image.json.kind, 'image');
  assert.equal(image.json.uv.length / 2, image.json.positions.length / 3);
  const picture = await request(studio.port,
    `/api/file?path=${encodeURIComponent(image.json.texture)}`);
  assert.equal(picture.status, 200);
  assert.match(picture.headers['content-type'], /image\/png/);
  // Back to the mesh the run below maps from.
  assert.equal((await api(studio.port, '/api/load', { side: 'source', path: source })).status, 200);
});

test('100 concurrent requests all answer, five times over', { timeout: 30000 }, async () => {
  for (let round = 0; round < 5; ++round) {
    const requests = [];
    for (let i = 0; i < 100; ++i) {
      requests.push(i % 2 ? api(studio.port, '/api/state')
        : api(studio.port, '/api/snap', { side: 'target', point: [0.01 * i, 0.2, 0.5] }));
    }
    const answers = await Promise.all(requests);
    for (const a of answers) assert.equal(a.status, 200);
  }
});

// Opens the event stream, reads its first event and hangs up.
function hangUpMidStream(port) {
  return new Promise((resolve, reject) => {
    const req = http.get({ host: '127.0.0.1', port, path: '/api/stream' }, (res) => {
      assert.match(res.headers['content-type'], /text\/event-stream/);
      res.once('data', (chunk) => {
        req.destroy();
        resolve(String(chunk));
      });
    });
    req.on('error', (e) => (e.code === 'ECONNRESET' ? resolve('') : reject(e)));
  });
}

test('a run streams, its saved job repeats with the CLI, hung-up streams do no harm', async () => {
  const first = await hangUpMidStream(studio.port);
  assert.match(first, /^data: /);
  const started = await api(studio.port, '/api/map', {
    'source-region': 'disk:0.5,0.5,0,0.4', 'target-region': 'boundary', particles: 600,
  });
  assert.equal(started.status, 200, JSON.stringify(started.json));
  // Clients that leave while the run streams.
  await Promise.all([hangUpMidStream(studio.port), hangUpMidStream(studio.port)]);
  const end = await waitForRun(studio.port, started.json.run);
  assert.equal(end.status, 'done', end.message);
  assert.equal(end.verdict.ok, true);
  const job = await request(studio.port, '/api/job');
  assert.match(job.headers['content-disposition'], /attachment/);
  const jobFile = path.join(out, 'server-job.json');
  fs.writeFileSync(jobFile, job.body);
  const report = JSON.parse((await request(studio.port, '/api/report')).body);
  const reportFile = path.join(out, 'server-report.json');
  const rerun = cli(['map', '--job', jobFile, '--report', reportFile]);
  assert.equal(rerun.status, 0, rerun.stderr);
  const again = JSON.parse(fs.readFileSync(reportFile, 'utf8'));
  assert.equal(again.particles, report.particles);
  assert.equal(again.folds, report.folds);
  for (const key of ['length', 'angle', 'initial']) {
    const a = report.energy[key], b = again.energy[key];
    assert.ok(Math.abs(a - b) <= 1e-9 * Math.max(1, Math.abs(a)), `energy.${key}: ${a} vs ${b}`);
  }
  // The paste job: the same map, painted.
  const pasteJob = await request(studio.port, '/api/job?command=paste');
  const pasteFile = path.join(out, 'server-paste-job.json');
  fs.writeFileSync(pasteFile, pasteJob.body);
  assert.equal(JSON.parse(pasteJob.body).command, 'paste');
  const paste = cli(['paste', '--job', pasteFile, '--out', path.join(out, 'paste'),
    '--report', path.join(out, 'paste-report.json')]);
  assert.equal(paste.status, 0, paste.stderr);
  const pasted = JSON.parse(fs.readFileSync(path.join(out, 'paste-report.json'), 'utf8'));
  const pastedEnergy = (pasted.map ?? pasted).energy;
  assert.ok(Math.abs(pastedEnergy.length - report.energy.length) <= 1e-9, 'paste repeats the map');
  // The result the page draws: ElasticPaint and the baseline on one grid and one colour scale.
  const result = await api(studio.port, '/api/result?baseline=lscm');
  assert.equal(result.status, 200);
  assert.deepEqual(result.json.methods.map((m) => m.name), ['elastic', 'lscm']);
  const n = result.json.grid.particles;
  for (const m of result.json.methods) {
    assert.equal(m.positions.length, 3 * n);
    assert.equal(m.colors.length, 3 * n);
  }
  // A warm re-solve for a smaller target disk.
  const warm = await api(studio.port, '/api/resolve', { spec: 'disk:0,0,1,0.8' });
  assert.equal(warm.status, 200, JSON.stringify(warm.json));
  assert.equal(warm.json.positions.length, 3 * n);
  assert.equal(warm.json.folds, 0);
  assert.equal(warm.json.converged, true, warm.json.stop);
  // A live update during a drag: stopped by its time budget after at least 10 steps, and the
  // next one continues from it.
  const budgeted = await api(studio.port, '/api/resolve', { spec: 'disk:0,0,1,0.7', budget_seconds: 1e-6 });
  assert.equal(budgeted.status, 200, JSON.stringify(budgeted.json));
  assert.equal(budgeted.json.converged, false);
  assert.equal(budgeted.json.stop, 'cancelled');
  assert.ok(budgeted.json.iterations >= 10, `${budgeted.json.iterations} iterations`);
  const bad = await api(studio.port, '/api/resolve', { spec: 'disk:0,0,1,0.7', budget_seconds: -1 });
  assert.equal(bad.status, 400);
  assert.match(bad.json.error, /budget_seconds/);
  assert.equal((await api(studio.port, '/api/state')).status, 200);
});
