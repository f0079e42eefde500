// ftd's web page: live wrench from the event stream, the rest from /api/v1/state once a second.
'use strict';
(function () {
  const AXES = ['Fx', 'Fy', 'Fz', 'Mx', 'My', 'Mz'];
  const WINDOW_S = 10;
  const COLORS = ['#d32f2f', '#388e3c', '#1976d2', '#f57c00', '#7b1fa2', '#00838f'];
  const $ = (id) => document.getElementById(id);
  const fmt = (v, d = 3) => (v === null || v === undefined ? '—' : Number(v).toFixed(d));
  let info = null;
  // Plot data: time (s) and one column per axis; the limits are constant columns.
  const times = [];
  const cols = AXES.map(() => []);
  const plots = {};
  window.ftd = { latest: null, state: null, plots, times, cols };

  function el(tag, text, cls) {
    const e = document.createElement(tag);
    if (text !== undefined) e.textContent = text;
    if (cls) e.className = cls;
    return e;
  }
  function fillDl(id, pairs) {
    const dl = $(id);
    dl.replaceChildren();
    for (const [k, v] of pairs) { dl.append(el('dt', k), el('dd', String(v))); }
  }

  function makePlot(id, axes, unit) {
    const series = [{}];
    for (const a of axes) series.push({ label: AXES[a] + ' (' + unit + ')', stroke: COLORS[a], width: 1.5 });
    const lim = [];
    if (info && info.rated_n_nm[axes[0]] !== null) {
      const r = info.rated_n_nm[axes[0]], o = info.overload_limit_n_nm[axes[0]];
      for (const [v, name, c] of [[r, 'rated', '#90a4ae'], [-r, '−rated', '#90a4ae'],
                                  [o, 'overload', '#e57373'], [-o, '−overload', '#e57373']]) {
        series.push({ label: name + ' ' + fmt(v, 1), stroke: c, dash: [6, 4], width: 1, points: { show: false } });
        lim.push(v);
      }
    }
    const width = Math.max(320, Math.min(760, (document.body.clientWidth - 80) / 2));
    const u = new uPlot({
      width, height: 260, series,
      scales: { x: { time: false } },
      axes: [{ label: 's ago' }, { label: unit }],
      legend: { live: false },
    }, [[]].concat(series.slice(1).map(() => [])), $(id));
    plots[id] = { u, axes, lim };
  }

  function redraw() {
    const now = times.length ? times[times.length - 1] : 0;
    const x = times.map((t) => t - now);
    for (const p of Object.values(plots)) {
      if (!p.axes) continue;
      const data = [x];
      for (const a of p.axes) data.push(cols[a]);
      for (const v of p.lim) data.push(x.map(() => v));
      p.u.setData(data);
    }
  }

  function onLive(s) {
    window.ftd.latest = s;
    const t = performance.now() / 1000;
    times.push(t);
    s.wrench_n_nm.forEach((v, i) => cols[i].push(v));
    while (times.length && times[0] < t - WINDOW_S) { times.shift(); cols.forEach((c) => c.shift()); }
    const r = $('readings');
    if (!r.children.length) {
      AXES.forEach((a, i) => {
        const d = el('div'); d.append(el('b', a + ' (' + info.units[i] + ')'), el('span', '', 'val'));
        d.querySelector('span').id = 'val-' + a; r.append(d);
      });
    }
    s.wrench_n_nm.forEach((v, i) => { $('val-' + AXES[i]).textContent = fmt(v); });
    showHealth(s.health);
    showStatus(s.status);
  }

  function showStatus(st) {
    const ul = $('status-words');
    ul.replaceChildren();
    if (!st.words.length) ul.append(el('li', 'no status bit set'));
    for (const w of st.words) ul.append(el('li', w));
  }

  function showHealth(h) {
    const badge = $('ne107');
    badge.textContent = h.ne107_words;
    badge.className = 'badge ' + (h.ne107 === 0 ? 'ok' : h.ne107 === 1 ? 'bad' : 'warn');
    $('health-state').textContent = !h.watch_on ? 'the health watch is off' :
      h.ne107_words + (h.findings.length ? ': ' + h.findings.map((f) => f.words).join(', ') : '') +
      (h.retare_suggested ? ' — re-tare suggested' : '');
    const tb = $('findings').tBodies[0];
    tb.replaceChildren();
    for (const f of h.findings) {
      const tr = el('tr');
      const worst = f.error_n_nm.map((e, i) => AXES[i] + ' ' + fmt(e) + ' ' + info.units[i]).join(', ');
      tr.append(el('td', f.words), el('td', worst), el('td', f.action));
      tr.dataset.cause = f.code;
      tb.append(tr);
    }
    if (!h.findings.length) { const tr = el('tr'); tr.append(el('td', 'no finding')); tb.append(tr); }
    const cov = $('coverage');
    cov.replaceChildren();
    for (const c of h.coverage) {
      const li = el('li', (c.judged_last_hour ? 'judged: ' : 'could not look: ') + c.words);
      li.dataset.cause = c.code;
      li.className = c.judged_last_hour ? 'judged' : 'not-judged';
      cov.append(li);
    }
  }

  function rainflow(rf) {
    // Grouped bars: per bin, one bar per axis; height on a log scale of the cycle count.
    const W = 560, H = 200, pad = 30, bins = rf.bin_upper_edges_pct_of_rated.length + 1;
    const counts = AXES.map((a) => rf.cycles[a]);
    const max = Math.max(1, ...counts.flat());
    const ns = 'http://www.w3.org/2000/svg';
    const svg = document.createElementNS(ns, 'svg');
    svg.setAttribute('viewBox', `0 0 ${W} ${H}`); svg.setAttribute('width', '100%');
    const bw = (W - pad) / bins;
    const y = (c) => (H - pad) * (1 - Math.log10(1 + c) / Math.log10(1 + max));
    for (let b = 0; b < bins; ++b) {
      AXES.forEach((a, i) => {
        const r = document.createElementNS(ns, 'rect');
        const yy = y(counts[i][b]);
        r.setAttribute('x', pad + b * bw + 2 + i * (bw - 4) / 6); r.setAttribute('width', (bw - 4) / 6 - 1);
        r.setAttribute('y', yy); r.setAttribute('height', H - pad - yy); r.setAttribute('fill', COLORS[i]);
        const tt = document.createElementNS(ns, 'title'); tt.textContent = `${a} bin ${b + 1}: ${counts[i][b]} cycles`;
        r.append(tt); svg.append(r);
      });
      const lo = b === 0 ? 2 : rf.bin_upper_edges_pct_of_rated[b - 1];
      const hi = b < bins - 1 ? rf.bin_upper_edges_pct_of_rated[b] : '';
      const t = document.createElementNS(ns, 'text');
      t.setAttribute('x', pad + b * bw + bw / 2); t.setAttribute('y', H - 12); t.setAttribute('font-size', 10);
      t.setAttribute('text-anchor', 'middle'); t.textContent = hi ? `${lo}–${hi} %` : `≥ ${lo} %`;
      svg.append(t);
    }
    const cap = document.createElementNS(ns, 'text');
    cap.setAttribute('x', 2); cap.setAttribute('y', 10); cap.setAttribute('font-size', 10);
    cap.textContent = counts.flat().some((c) => c > 0)
      ? `full cycles per axis (bars Fx … Mz, log scale, max ${max}); bins: range in % of rated`
      : 'no full cycle counted yet (bins: range in % of rated)';
    svg.append(cap);
    $('plot-rainflow').replaceChildren(svg);
  }

  function onState(s) {
    window.ftd.state = s;
    const c = s.calibration;
    fillDl('calibration', [['active slot', c.slot_name], ['serial', c.serial ?? '—'], ['date', c.date || '—'],
      ['CRC-32', '0x' + c.crc32.toString(16).padStart(8, '0')], ['file', c.file || '(built-in)'],
      ['temperature', s.temperature_c === null ? 'none' : fmt(s.temperature_c, 2) + ' °C']]);
    const p = s.payload, tt = s.tool_transform;
    fillDl('payload', [['payload mass', p.mass_kg === null ? '—' : fmt(p.mass_kg, 3) + ' kg'],
      ['payload CRC-32', '0x' + p.crc32.toString(16).padStart(8, '0')],
      ['gravity compensation', p.compensation_on ? 'on' : 'off'],
      ['tool translation', tt.translation_m.map((v) => fmt(v, 4)).join(', ') + ' m'],
      ['tool rotation', tt.rotation_deg.map((v) => fmt(v, 2)).join(', ') + ' °'],
      ['low-pass', s.settings.filter_length + ' samples'], ['decimation', s.settings.decimation]]);
    const tb = $('tares').tBodies[0];
    tb.replaceChildren();
    for (const r of s.tare_history) {
      const tr = el('tr');
      tr.append(el('td', r.number), el('td', r.source), el('td', r.time_s), el('td', fmt(r.temperature_c, 1)),
        el('td', r.load_n_nm.map((v) => fmt(v)).join(', ')));
      tb.append(tr);
    }
    if (!s.tare_history.length) { const tr = el('tr'); tr.append(el('td', 'no tare yet')); tb.append(tr); }
    fillDl('overload', [['events', s.overload.events],
      ...s.overload.peaks_n_nm.map((v, i) => ['peak ' + AXES[i], fmt(v) + ' ' + info.units[i]])]);
    rainflow(s.rainflow);
    const rt = s.runtime, cl = rt.clients || {};
    const pairs = [['sample rate', fmt(rt.sample_rate_hz, 1) + ' Hz (configured ' + info.rate_hz + ')'],
      ['late samples', s.late_samples], ['web streams open', rt.http.streams_open]];
    if (cl.modbus_tcp) pairs.push(['Modbus TCP', cl.modbus_tcp.connections_accepted + ' connections, ' + cl.modbus_tcp.requests + ' requests']);
    if (cl.rdt) pairs.push(['RDT', cl.rdt.requests + ' requests']);
    pairs.push(['MQTT', s.mqtt.connected ? 'connected, ' + s.mqtt.published + ' published' : (cl.mqtt ? 'not connected' : 'off')]);
    fillDl('runtime', pairs);
    const f = $('settings');
    if (!f.dataset.filled) {
      f.filter_length.value = s.settings.filter_length;
      f.cal_slot.value = c.slot;
      f.health_thresholds_51_59.value = s.settings.health_thresholds_51_59.join(',');
      f.dataset.filled = '1';
    }
  }

  function message(text, ok) { const m = $('message'); m.textContent = text; m.className = ok ? 'ok' : 'error'; }
  async function post(path, body) {
    try {
      const r = await fetch(path, { method: 'POST', headers: { 'Content-Type': 'application/json' }, body: JSON.stringify(body) });
      const j = await r.json();
      if (r.ok) message('done: ' + (body.command || Object.keys(body).join(', ')), true);
      else message(j.error || ('HTTP ' + r.status), false);
    } catch (e) { message('no answer from the sensor: ' + e, false); }
  }

  async function pollState() {
    try {
      const r = await fetch('api/v1/state');
      if (r.ok) onState(await r.json());
    } catch (e) { /* the stream's badge shows the connection */ }
    setTimeout(pollState, 1000);
  }

  async function start() {
    info = await (await fetch('api/v1/info')).json();
    if (info.write_protected) message('this sensor is write-protected: commands are refused', false);
    const lim = info.rated_n_nm[0] === null ? 'no rated range' :
      'dashed: rated range ±' + info.rated_n_nm.map((v, i) => fmt(v, 1) + ' ' + info.units[i]).join(', ') +
      '; overload limit 105 % of rated';
    $('limits').textContent = lim;
    makePlot('plot-force', [0, 1, 2], 'N');
    makePlot('plot-moment', [3, 4, 5], 'N·m');
    document.querySelectorAll('button[data-command]').forEach((b) =>
      b.addEventListener('click', () => post('api/v1/command', { command: b.dataset.command })));
    $('settings').addEventListener('submit', (ev) => {
      ev.preventDefault();
      const f = ev.target;
      const th = f.health_thresholds_51_59.value.split(',').map((v) => Number(v.trim()));
      post('api/v1/settings', { filter_length: Number(f.filter_length.value), cal_slot: Number(f.cal_slot.value),
        health_thresholds_51_59: th });
    });
    const es = new EventSource('api/v1/stream');
    es.addEventListener('live', (ev) => onLive(JSON.parse(ev.data)));
    es.onopen = () => { $('conn').textContent = 'live'; $('conn').className = 'badge ok'; };
    es.onerror = () => { $('conn').textContent = 'reconnecting…'; $('conn').className = 'badge bad'; };
    setInterval(redraw, 100);
    pollState();
  }
  start();
})();
