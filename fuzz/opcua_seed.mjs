// Records what a real OPC UA client sends: node-opcua (tests/opcua) runs one session against ftd
// through a TCP relay that writes the client's bytes to a file, a seed for fuzz_opcua (first byte 0:
// the input is fed as it is). The session: Hello, OpenSecureChannel (None), CreateSession,
// ActivateSession (anonymous), Browse of the sensor object, Read of the wrench and DeviceHealth, a
// subscription with two monitored items for a few publish cycles, the Tare method, CloseSession.
// Usage: node fuzz/opcua_seed.mjs FTD OUT  (e.g. build/bin/ftd fuzz/corpus/opcua/node_opcua_session)
import { spawn } from 'node:child_process';
import { mkdtempSync, readFileSync, rmSync, openSync, writeFileSync } from 'node:fs';
import { createRequire } from 'node:module';
import { createServer, connect as tcpConnect } from 'node:net';
import { tmpdir } from 'node:os';
import { join, dirname } from 'node:path';
import { fileURLToPath } from 'node:url';

const here = dirname(fileURLToPath(import.meta.url));
const require = createRequire(join(here, '..', 'tests', 'opcua', 'package.json'));
const { OPCUAClient, MessageSecurityMode, SecurityPolicy, AttributeIds, ClientSubscription,
  ClientMonitoredItem, TimestampsToReturn } = require('node-opcua-client');
const { OPCUACertificateManager } = require('node-opcua-certificate-manager');

const [ftdBin, out] = process.argv.slice(2);
if (!ftdBin || !out) { console.error('usage: node fuzz/opcua_seed.mjs FTD OUT'); process.exit(2); }
const dir = mkdtempSync(join(tmpdir(), 'ftd-opcua-seed-'));
const sleep = (ms) => new Promise((r) => setTimeout(r, ms));

const errPath = join(dir, 'ftd.err');
const ftd = spawn(ftdBin, ['--adc', 'sim', '--print-hz', '0', '--opcua', '127.0.0.1:0'],
  { stdio: ['ignore', 'ignore', openSync(errPath, 'w')] });
let port = 0;
for (let i = 0; i < 200 && !port; ++i) {
  const m = readFileSync(errPath, 'utf8').match(/serving OPC UA on opc\.tcp:\/\/[^:]+:(\d+)/);
  if (m) port = Number(m[1]); else await sleep(50);
}
if (!port) { ftd.kill(); throw new Error('ftd did not announce its OPC UA port'); }

const sent = [];
const relay = createServer((c) => {
  const s = tcpConnect(port, '127.0.0.1');
  c.on('data', (d) => { sent.push(Buffer.from(d)); s.write(d); });
  s.on('data', (d) => c.write(d));
  c.on('close', () => s.end());
  s.on('close', () => c.end());
});
await new Promise((r) => relay.listen(0, '127.0.0.1', r));
const url = `opc.tcp://127.0.0.1:${relay.address().port}`;

try {
  const client = OPCUAClient.create({ endpointMustExist: false, securityMode: MessageSecurityMode.None,
    securityPolicy: SecurityPolicy.None, connectionStrategy: { maxRetry: 0 },
    clientCertificateManager: new OPCUACertificateManager({ rootFolder: join(dir, 'pki'), automaticallyAcceptUnknownCertificate: true }) });
  await client.connect(url);
  const session = await client.createSession();
  await session.browse('ns=1;s=Sensor');
  await session.read(['Fx', 'Fy', 'Fz', 'Mx', 'My', 'Mz'].map((a) => ({ nodeId: 'ns=1;s=Sensor.Wrench.' + a, attributeId: AttributeIds.Value }))
    .concat([{ nodeId: 'ns=1;s=Sensor.DeviceHealth', attributeId: AttributeIds.Value }]));
  const sub = ClientSubscription.create(session, { requestedPublishingInterval: 10, requestedMaxKeepAliveCount: 10,
    requestedLifetimeCount: 100, maxNotificationsPerPublish: 0, publishingEnabled: true, priority: 1 });
  for (const id of ['ns=1;s=Sensor.Wrench.Fz', 'ns=1;s=Sensor.Sequence']) {
    ClientMonitoredItem.create(sub, { nodeId: id, attributeId: AttributeIds.Value },
      { samplingInterval: 10, queueSize: 10, discardOldest: true }, TimestampsToReturn.Both);
  }
  await sleep(100);
  await session.call({ objectId: 'ns=1;s=Sensor', methodId: 'ns=1;s=Sensor.Tare', inputArguments: [] });
  await sub.terminate();
  await session.close();
  await client.disconnect();
  const bytes = Buffer.concat([Buffer.from([0]), ...sent]);
  writeFileSync(out, bytes);
  console.log(`${out}: ${bytes.length} bytes`);
} finally {
  relay.close();
  ftd.kill('SIGTERM');
  rmSync(dir, { recursive: true, force: true });
}
process.exit(0);
