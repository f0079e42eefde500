// ftd's web page in a real browser: Debian's chromium driven by puppeteer-core. Starts the real ftd
// (simulated sensor, a 50 Hz mains effect), loads the page, and checks: no request leaves
// 127.0.0.1; the plotted and displayed wrench match a Modbus read (mbpoll) of the same sample
// within one LSB; the finding appears in words; Tare zeroes the reading and adds a tare history
// row with source "web". Writes a screenshot. Usage: node page_test.mjs FTD_BINARY SCREENSHOT.png
import { spawn, execFileSync } from 'node:child_process';
import { mkdtempSync, readFileSync, rmSync, openSync } from 'node:fs';
import { tmpdir } from 'node:os';
import { join } from 'node:path';
import assert from 'node:assert/strict';
import puppeteer from 'puppeteer-core';

const [ftdBin, shotPath] = process.argv.slice(2);
if (!ftdBin || !shotPath) { console.error('usage: node page_test.mjs FTD SCREENSHOT.png'); process.exit(2); }
const dir = mkdtempSync(join(tmpdir(), 'ftd-web-'));
const errPath = join(dir, 'ftd.err');
const ftd = spawn(ftdBin, ['--modbus-tcp', '127.0.0.1:0', '--http', '127.0.0.1:0', '--print-hz', '0',
  '--sim-wrench', '10,-4,-50,0.2,0.5,-0.1', '--sim-span-s', '60',
  '--sim-effect', 'mains_interference:freq_hz=50,amplitude_mvv=0.002'],
{ stdio: ['ignore', 'ignore', openSync(errPath, 'w')] });
let browser = null;
const sleep = (ms) => new Promise((r) => setTimeout(r, ms));
const deadline = setTimeout(() => { console.error('FAIL: over 60 s'); cleanup(1); }, 60000);

function cleanup(code) {
  clearTimeout(deadline);
  const done = () => { ftd.kill('SIGTERM'); rmSync(dir, { recursive: true, force: true }); process.exit(code); };
  if (browser) browser.close().catch(() => {}).finally(done); else done();
}

async function servedPort(what) {
  const re = new RegExp('serving ' + what + ' on [^:]+:([0-9]+)');
  for (let i = 0; i < 300; ++i) {
    const m = readFileSync(errPath, 'utf8').match(re);
    if (m) return Number(m[1]);
    await sleep(50);
  }
  throw new Error('ftd did not serve ' + what + ':\n' + readFileSync(errPath, 'utf8'));
}

/// mbpoll (an independent Modbus client): 0-based input registers, high word first.
function mbpoll(port, type, addr, count) {
  const out = execFileSync('mbpoll', ['-m', 'tcp', '-p', String(port), '-a', '1', '-t', type, '-B', '-0',
    '-r', String(addr), '-c', String(count), '-1', '127.0.0.1'], { encoding: 'utf8' });
  return [...out.matchAll(/\[(\d+)\]:\s+(\S+)/g)].map((m) => Number(m[2]));
}

async function main() {
  const modbus = await servedPort('Modbus TCP');
  const http = await servedPort('the web page');
  // One published sample a second, so that the page and mbpoll can see the same one.
  execFileSync('mbpoll', ['-m', 'tcp', '-p', String(modbus), '-a', '1', '-t', '4', '-0', '-r', '2', '-1',
    '127.0.0.1', '1000'], { encoding: 'utf8' });
  browser = await puppeteer.launch({
    executablePath: '/usr/bin/chromium',
    userDataDir: join(dir, 'profile'),
    args: ['--headless', '--no-sandbox', '--disable-gpu', '--disable-quic', '--no-first-run',
      '--disable-background-networking', '--disable-component-update', '--disable-sync',
      '--disable-dev-shm-usage'],
  });
  const page = await browser.newPage();
  await page.setViewport({ width: 1400, height: 1500 });
  const requests = [];
  page.on('request', (r) => requests.push(r.url()));
  const pageErrors = [];
  page.on('pageerror', (e) => pageErrors.push(String(e)));
  await page.goto(`http://127.0.0.1:${http}/`, { waitUntil: 'domcontentloaded' });
  await page.waitForFunction(() => window.ftd && window.ftd.latest && window.ftd.state, { timeout: 15000 });

  // Plotted and displayed values against mbpoll, same sample (sequence, input registers 2–3).
  let matched = 0;
  for (let i = 0; i < 20 && matched < 1; ++i) {
    const seq = mbpoll(modbus, '3:int', 2, 1)[0] >>> 0;
    const floats = mbpoll(modbus, '3:float', 6, 6);
    const ints = mbpoll(modbus, '3:int', 18, 6);
    if ((mbpoll(modbus, '3:int', 2, 1)[0] >>> 0) !== seq) continue;
    let got = null;
    for (let k = 0; k < 30; ++k) {
      got = await page.evaluate(() => ({
        seq: window.ftd.latest.sequence,
        plotted: window.ftd.cols.map((c) => c[c.length - 1]),
        plotData: Object.values(window.ftd.plots).map((p) => p.u.data.slice(1, 4).map((s) => s[s.length - 1])),
        shown: ['Fx', 'Fy', 'Fz', 'Mx', 'My', 'Mz'].map((a) => document.getElementById('val-' + a).textContent),
      }));
      if (got.seq === seq) break;
      await sleep(50);
    }
    if (got.seq !== seq) continue;
    const uplot = got.plotData.flat();  // what uPlot holds: Fx Fy Fz, then Mx My Mz
    for (let a = 0; a < 6; ++a) {
      // mbpoll prints floats to 6 significant digits; one LSB of the int registers is 0.001.
      assert.ok(Math.abs(got.plotted[a] - floats[a]) <= 0.001, `plotted axis ${a}: ${got.plotted[a]} vs ${floats[a]}`);
      assert.ok(Math.abs(uplot[a] - floats[a]) <= 0.001, `uPlot axis ${a}: ${uplot[a]} vs ${floats[a]}`);
      assert.ok(Math.abs(Number(got.shown[a]) * 1000 - ints[a]) <= 1, `shown axis ${a}: ${got.shown[a]} vs ${ints[a]} mN`);
    }
    matched += 1;
  }
  assert.equal(matched, 1, 'the page never showed the sample mbpoll read');

  // The injected mains pick-up appears as a finding in words.
  await page.waitForFunction(() => document.querySelector('#findings tbody').textContent.includes('mains pick-up at 50 Hz'),
    { timeout: 15000 });
  const findingRow = await page.$eval('#findings tbody', (t) => t.textContent);
  assert.match(findingRow, /Fz/);
  assert.match(await page.$eval('#ne107', (e) => e.textContent), /maintenance required/);

  // Tare: the reading goes to zero, a history row with source "web" appears.
  await page.click('#btn-tare');
  await page.waitForFunction(() => document.querySelector('#tares tbody').textContent.includes('web'), { timeout: 15000 });
  await page.waitForFunction(() => Math.abs(window.ftd.latest.wrench_n_nm[2]) < 2, { timeout: 15000 });
  const sourceModbus = mbpoll(modbus, '3', 212, 1)[0];
  assert.equal(sourceModbus, 4, 'tare history source over Modbus (4 = web)');
  const fz = Number(await page.$eval('#val-Fz', (e) => e.textContent));
  assert.ok(Math.abs(fz) < 2, `Fz shown after the tare: ${fz}`);
  assert.match(await page.$eval('#message', (e) => e.textContent), /done: tare/);

  await sleep(1500);  // a few points of the tared reading in the plot
  await page.screenshot({ path: shotPath, fullPage: true });

  const outside = requests.filter((u) => new URL(u).hostname !== '127.0.0.1');
  assert.deepEqual(outside, [], 'requests that left 127.0.0.1');
  assert.deepEqual(pageErrors, [], 'JavaScript errors on the page');
  console.log(`PASS: ${requests.length} requests, all to 127.0.0.1; screenshot ${shotPath}`);
}

main().then(() => cleanup(0)).catch((e) => { console.error('FAIL:', e.message || e); cleanup(1); });
