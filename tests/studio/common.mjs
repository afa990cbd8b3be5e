// Shared by the studio's tests: start `elastic studio` on a free loopback port, talk to it, run the
// CLI. Environment (set by tests/CMakeLists.txt): ELASTIC_TOOL, ELASTIC_SHARED_DIR, STUDIO_OUT.
import { spawn, spawnSync } from 'node:child_process';
import http from 'node:http';
import net from 'node:net';

export const tool = process.env.ELASTIC_TOOL;
export const shared = process.env.ELASTIC_SHARED_DIR;
export const out = process.env.STUDIO_OUT;

// Starts the server; resolves {url, port, process} once it prints its URL.
export function startStudio(args) {
  return new Promise((resolve, reject) => {
    const child = spawn(tool, ['studio', '--port', '0', ...args], { stdio: ['ignore', 'pipe', 'pipe'] });
    let text = '';
    let errors = '';
    const timer = setTimeout(() => reject(new Error(`studio did not start: ${errors}`)), 60000);
    child.stdout.on('data', (chunk) => {
      text += chunk;
      const match = text.match(/open (http:\/\/127\.0\.0\.1:(\d+)\/)/);
      if (match) {
        clearTimeout(timer);
        resolve({ url: match[1], port: Number(match[2]), process: child });
      }
    });
    child.stderr.on('data', (chunk) => { errors += chunk; });
    child.on('exit', (code) => {
      clearTimeout(timer);
      reject(new Error(`studio exited with ${code}: ${errors}`));
    });
  });
}

// One raw HTTP request (the path is sent as given, headers exactly as given): {status, headers, body}.
export function request(port, path, { method = 'GET', headers = {}, body } = {}) {
  return new Promise((resolve, reject) => {
    const options = {
      host: '127.0.0.1', port, path, method,
      headers: { Host: `127.0.0.1:${port}`, ...headers },
    };
    const req = http.request(options, (res) => {
      let data = '';
      res.setEncoding('utf8');
      res.on('data', (chunk) => { data += chunk; });
      res.on('end', () => resolve({ status: res.statusCode, headers: res.headers, body: data }));
    });
    req.on('error', reject);
    if (body !== undefined) {
      req.setHeader('Content-Type', 'application/json');
      req.end(JSON.stringify(body));
    } else {
      req.end();
    }
  });
}

export async function api(port, path, body) {
  const answer = await request(port, path, body === undefined ? {} : { method: 'POST', body });
  return { status: answer.status, json: JSON.parse(answer.body) };
}

// A raw request line over a socket (paths node's http would refuse or normalise). The request
// says `Connection: close`: the server ends the connection after answering (half-closing our side
// first could make it drop the answer).
export function rawRequest(port, text) {
  return new Promise((resolve, reject) => {
    const socket = net.connect(port, '127.0.0.1', () => socket.write(text));
    let data = '';
    socket.setEncoding('utf8');
    socket.on('data', (chunk) => { data += chunk; });
    socket.on('end', () => resolve(data));
    socket.on('error', reject);
  });
}

// Runs the CLI: {status, stdout, stderr}.
export function cli(args) {
  const r = spawnSync(tool, args, { encoding: 'utf8', timeout: 300000 });
  return { status: r.status, stdout: r.stdout, stderr: r.stderr };
}

// Waits until the run ends (long poll); returns the final state.
export async function waitForRun(port, run, seconds = 300) {
  const deadline = Date.now() + seconds * 1000;
  let version = -1;
  while (Date.now() < deadline) {
    const { json } = await api(port, `/api/events?version=${version}&frame=1000000000&wait=5`);
    version = json.version;
    if (json.run === run && (json.status === 'done' || json.status === 'failed')) return json;
  }
  throw new Error(`run ${run} did not end within ${seconds} s`);
}
