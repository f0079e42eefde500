// The cost of ftd's OPC UA subscriptions, measured from outside on the real binary: two paced ftds
// at RATE Hz side by side, one serving SUBS subscriptions (each ITEMS wrench axes sampled and
// published every 10 ms, one node-opcua client), the other serving none; whole-process CPU (utime +
// stime from /proc) over the same windows, REPS repetitions, in % of one core.
// Usage: node bench/opcua_load.mjs FTD [--rate 8000] [--subs 10] [--items 6] [--reps 5] [--window 10]
// (node-opcua from tests/opcua: ./ftstack.sh deps)
import { spawn } from 'node:child_process';
import { mkdtempSync, readFileSync, readdirSync, rmSync, openSync } from 'node:fs';
import { createRequire } from 'node:module';
import { tmpdir, loadavg } from 'node:os';
import { join, dirname } from 'node:path';
import { fileURLToPath } from 'node:url';

const here = dirname(fileURLToPath(import.meta.url));
const require = createRequire(join(here, '..', 'tests', 'opcua', 'package.json'));
const { OPCUAClient, MessageSecurityMode, SecurityPolicy, AttributeIds, ClientSubscription,
  ClientMonitoredItem, TimestampsToReturn } = require('node-opcua-client');
const { OPCUACertificateManager } = require('node-opcua-certificate-manager');

const args = process.argv.slice(2);
const ftdBin = args[0];
const opt = (name, def) => { const i = args.indexOf('--' + name); return i > 0 ? Number(args[i + 1]) : def; };
const rate = opt('rate', 8000);
const subs = opt('subs', 10);
const items = opt('items', 6);  // monitored items per subscription: the first ITEMS wrench axes
const reps = opt('reps', 5);
const window = opt('window', 10);
if (!ftdBin) { console.error('usage: node bench/opcua_load.mjs FTD [--rate 8000] [--subs 10] [--reps 5] [--window 10]'); process.exit(2); }
const dir = mkdtempSync(join(tmpdir(), 'ftd-opcua-bench-'));
const sleep = (ms) => new Promise((r) => setTimeout(r, ms));
const clk = 100;  // USER_HZ (sysconf(_SC_CLK_TCK) on Linux)

async function startFtd(name) {
  const errPath = join(dir, name + '.err');
  const p = spawn(ftdBin, ['--adc', 'sim', '--rate-hz', String(rate), '--print-hz', '0', '--opcua', '127.0.0.1:0'],
    { stdio: ['ignore', 'ignore', openSync(errPath, 'w')] });
  for (let i = 0; i < 600; ++i) {
    const m = readFileSync(errPath, 'utf8').match(/serving OPC UA on (opc\.tcp:\/\/[^ ]+)/);
    if (m) return { p, url: m[1] };
    await sleep(50);
  }
  p.kill();
  throw new Error(name + ': ftd did not announce its OPC UA port');
}

function ticks(pid, tid) {
  const path = tid ? `/proc/${pid}/task/${tid}/stat` : `/proc/${pid}/stat`;
  const f = readFileSync(path, 'utf8').split(')').pop().trim().split(/\s+/);
  return Number(f[11]) + Number(f[12]);  // utime, stime (fields 14 and 15)
}

// The server thread (named ftd-opcua): its own CPU shows the cost without the sampling thread's
// run-to-run spread.
function serverThread(pid) {
  for (const t of readdirSync(`/proc/${pid}/task`)) {
    if (readFileSync(`/proc/${pid}/task/${t}/comm`, 'utf8').trim() === 'ftd-opcua') return t;
  }
  throw new Error('ftd has no ftd-opcua thread');
}

async function load(url, n) {
  const client = OPCUAClient.create({ endpointMustExist: false, securityMode: MessageSecurityMode.None,
    securityPolicy: SecurityPolicy.None, connectionStrategy: { maxRetry: 0 },
    clientCertificateManager: new OPCUACertificateManager({ rootFolder: join(dir, 'pki'), automaticallyAcceptUnknownCertificate: true }) });
  await client.connect(url);
  const session = await client.createSession();
  const counter = { changes: 0 };
  for (let s = 0; s < n; ++s) {
    const sub = ClientSubscription.create(session, { requestedPublishingInterval: 10, requestedMaxKeepAliveCount: 100,
      requestedLifetimeCount: 1000, maxNotificationsPerPublish: 0, publishingEnabled: true, priority: 1 });
    for (const a of ['Fx', 'Fy', 'Fz', 'Mx', 'My', 'Mz'].slice(0, items)) {
      const item = ClientMonitoredItem.create(sub, { nodeId: 'ns=1;s=Sensor.Wrench.' + a, attributeId: AttributeIds.Value },
        { samplingInterval: 10, queueSize: 10, discardOldest: true }, TimestampsToReturn.Both);
      item.on('changed', () => { ++counter.changes; });
    }
  }
  return { client, session, counter };
}

const median = (v) => { const s = [...v].sort((a, b) => a - b); const m = s.length >> 1; return s.length % 2 ? s[m] : (s[m - 1] + s[m]) / 2; };
const withS = [];
const withoutS = [];
const threadS = [];
try {
  for (let rep = 0; rep < reps; ++rep) {
    const a = await startFtd('subs');
    const b = await startFtd('none');
    const l = await load(a.url, subs);
    await sleep(2000);
    const at = serverThread(a.p.pid);
    const t0 = Date.now(); const a0 = ticks(a.p.pid); const b0 = ticks(b.p.pid); const c0 = l.counter.changes;
    const s0 = ticks(a.p.pid, at);
    await sleep(window * 1000);
    const t1 = Date.now(); const a1 = ticks(a.p.pid); const b1 = ticks(b.p.pid); const c1 = l.counter.changes;
    const s1 = ticks(a.p.pid, at);
    await l.session.close();
    await l.client.disconnect();
    a.p.kill('SIGTERM'); b.p.kill('SIGTERM');
    const s = (t1 - t0) / 1000;
    const w = 100 * (a1 - a0) / clk / s;
    const n = 100 * (b1 - b0) / clk / s;
    const th = 100 * (s1 - s0) / clk / s;
    withS.push(w); withoutS.push(n); threadS.push(th);
    console.log(`  rep ${rep + 1}/${reps} at ${rate} Hz over ${window} s: ${subs} subscriptions ${w.toFixed(2)} %, ` +
      `none ${n.toFixed(2)} %, difference ${(w - n >= 0 ? '+' : '') + (w - n).toFixed(2)} %, its server thread ${th.toFixed(2)} % (${c1 - c0} changes; ` +
      `load average ${loadavg()[0].toFixed(1)})`);
    await sleep(500);
  }
  const d = withS.map((w, i) => w - withoutS[i]);
  console.log(`ftd CPU at ${rate} Hz, % of one core: ${subs} subscriptions (${items} items each, 10 ms) median ` +
    `${median(withS).toFixed(2)}, none ${median(withoutS).toFixed(2)}; difference median ` +
    `${median(d) >= 0 ? '+' : ''}${median(d).toFixed(2)} (range ${Math.min(...d).toFixed(2)} … ` +
    `${Math.max(...d).toFixed(2)}), ratio ${(median(withS) / median(withoutS)).toFixed(2)}; its server thread median ` +
    `${median(threadS).toFixed(2)} (range ${Math.min(...threadS).toFixed(2)} … ${Math.max(...threadS).toFixed(2)})`);
} finally {
  rmSync(dir, { recursive: true, force: true });
}
process.exit(0);
