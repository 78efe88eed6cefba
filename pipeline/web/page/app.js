// The operator page: the state once a second from /api/events, the last
// minute's plots from /api/history, the preview from /stream.mjpeg.
'use strict';

const $ = (id) => document.getElementById(id);
const fixed = (value, digits) => (typeof value === 'number' ? value.toFixed(digits) : '–');

function text(id, value) {
  const node = $(id);
  if (node.textContent !== value) node.textContent = value;
}

function health(node, good, goodText, badText) {
  node.textContent = good ? goodText : badText;
  node.className = good ? 'ok' : 'bad';
}

function rows(table, entries) {
  const body = table.tBodies[0];
  body.replaceChildren(...entries.map((cells) => {
    const row = document.createElement('tr');
    for (const cell of cells) {
      const td = document.createElement('td');
      if (cell instanceof Node) td.append(cell); else td.textContent = cell;
      row.append(td);
    }
    return row;
  }));
}

function status(good, words) {
  const span = document.createElement('span');
  span.textContent = words;
  span.className = good ? 'ok' : 'bad';
  return span;
}

function show(state) {
  text('board', state.board.name);
  const badge = $('health');
  const live = state.camera.connected && !state.renderer_lost &&
      state.outputs.every((o) => o.connected);
  badge.textContent = live ? 'live' : 'fault';
  badge.className = 'badge ' + (live ? 'ok' : 'bad');
  text('lens-source', state.lens.source);
  const counts = state.lens.counts[$('mark-axis').value];
  text('mark-counts', counts === null ? '–' : String(counts));
  const frame = state.frame;
  if (frame) {
    text('focus', fixed(frame.focus_m, 3));
    text('iris', fixed(frame.f_number, 2));
    text('zoom', fixed(frame.focal_length_mm, 1));
    text('frame', String(frame.frame));
    health($('lens-fresh'), frame.lens_fresh, 'current', 'held (stale)');
    // A mean: the frame budget gives fractions of a ray (frame_budget.h).
    text('rpp', Number.isInteger(frame.rpp) ? String(frame.rpp) : fixed(frame.rpp, 2));
    text('traced', (100 * frame.traced).toFixed(0) + ' %');
  }
  const pose = state.pose;
  // A marker pose says how it was found: markers read, corners followed or
  // the blurred board aligned. Before the first, the composite is the
  // camera image alone.
  health($('pose'), pose.fresh !== false,
         pose.source + (pose.fresh === false ? ', held' : pose.found_by ? ', by ' + pose.found_by : ''),
         pose.source + (pose.known === false ? ', none yet: camera image only' : ', held (stale)'));
  text('in-fps', fixed(state.in_fps, 1));
  text('out-fps', fixed(state.out_fps, 1));
  text('executor', state.executor);
  rows($('stages'), Object.entries(state.latency).map(([name, l]) =>
      [name.replaceAll('_', ' '), l.median_ms.toFixed(2), l.p99_ms.toFixed(2)]));
  rows($('devices'), [
    ['camera', state.camera.name, status(state.camera.connected, state.camera.connected ? 'ok' : 'lost')],
    ...state.outputs.map((o) => ['output', o.name, status(o.connected, o.connected ? 'ok' : o.detail)]),
    ['lens', state.lens.source, status(state.lens.connected, state.lens.connected ? (state.lens.fresh ? 'ok' : 'stale') : 'lost')],
  ]);
  const c = state.counts;
  rows($('drops'), [
    ['camera', c.camera_dropped], ['render busy', c.render_busy], ['output busy', c.output_busy],
    ['render failed', c.render_failed], ['repeats', c.repeats], ['placeholders', c.placeholders],
    ['lens late', c.lens_late], ['output errors', c.sink_errors],
  ].map(([name, n]) => [name, String(n)]));
  $('freeze').setAttribute('aria-pressed', String(state.frozen));
  const recording = state.recording;
  $('record').setAttribute('aria-pressed', String(recording !== null));
  $('record').textContent = recording ? 'stop recording (' + recording.frames + ' frames)' : 'record';
  $('record').disabled = !state.can_record;
  $('reload').disabled = !state.can_reload;
  // A reload's outcome (taken, or refused and why) once it comes.
  if (state.reload) {
    text('reload-last', state.reload.last || 'none since the start');
    if (reloadsSeen !== null && state.reload.outcomes > reloadsSeen) text('message', state.reload.last);
    reloadsSeen = state.reload.outcomes;
  }
}
let reloadsSeen = null;

// Series over the last minute on a shared time axis, each scaled to its own range.
function plot(canvas, t, series) {
  const g = canvas.getContext('2d');
  const w = canvas.width, h = canvas.height, pad = 4;
  g.clearRect(0, 0, w, h);
  g.strokeStyle = '#2a2a2a';
  for (let s = 0; s <= 60; s += 10) {
    const x = pad + (w - 2 * pad) * (1 - s / 60);
    g.beginPath(); g.moveTo(x, 0); g.lineTo(x, h); g.stroke();
  }
  for (const { values, colour, log } of series) {
    const v = log ? values.map((x) => Math.log(Math.max(x, 1e-3))) : values;
    if (v.length < 2) continue;
    let lo = Math.min(...v), hi = Math.max(...v);
    if (hi - lo < 1e-9) { lo -= 1; hi += 1; }
    g.strokeStyle = colour;
    g.beginPath();
    v.forEach((y, i) => {
      const x = pad + (w - 2 * pad) * (1 + t[i] / 60);
      const py = h - pad - (h - 2 * pad) * (y - lo) / (hi - lo);
      if (i === 0) g.moveTo(x, py); else g.lineTo(x, py);
    });
    g.stroke();
  }
}

async function refreshHistory() {
  try {
    const reply = await fetch('/api/history', { cache: 'no-store' });
    if (!reply.ok) return;
    const h = await reply.json();
    plot($('lens-plot'), h.t_s, [
      { values: h.focus_m, colour: '#58a6ff', log: true },
      { values: h.f_number, colour: '#f0883e', log: true },
      { values: h.focal_length_mm, colour: '#a371f7' },
    ]);
    plot($('latency-plot'), h.t_s, [
      { values: h.latency_ms, colour: '#3fb950' },
      { values: h.render_ms, colour: '#d29922' },
    ]);
  } catch (e) { /* the next second tries again */ }
}

async function act(name, body) {
  const reply = await fetch('/api/' + name, {
    method: 'POST', headers: { 'Content-Type': 'application/json' }, body: JSON.stringify(body),
  });
  const answer = await reply.json().catch(() => ({}));
  text('message', answer.error ?? answer.reload ?? '');
  return answer;
}

$('freeze').addEventListener('click', () =>
  act('freeze', { frozen: $('freeze').getAttribute('aria-pressed') !== 'true' }));
$('reload').addEventListener('click', () => act('reload', {}));
$('mark').addEventListener('submit', async (event) => {
  event.preventDefault();
  const answer = await act('mark', { axis: $('mark-axis').value, value: Number($('mark-value').value) });
  if (answer.file) text('message', answer.axis + ' ' + answer.value + ' at ' + answer.counts +
      ' counts, in ' + answer.file);
});
$('record').addEventListener('click', async () => {
  const answer = await act('record', { recording: $('record').getAttribute('aria-pressed') !== 'true' });
  if (answer.file) text('message', (answer.recording ? 'recording to ' : 'recorded ') + answer.file +
      (answer.frames !== undefined ? ' (' + answer.frames + ' frames)' : ''));
});
$('capture').addEventListener('click', async () => {
  const answer = await act('view', {});
  if (answer.file) text('message', 'view ' + answer.views + ' at ' + answer.at + ' saved (' +
      (answer.markers !== undefined ? answer.markers_seen + ' of ' + answer.markers + ' markers seen'
                                    : 'not checked: ' + answer.unchecked) +
      '): ' + answer.file + '. Fit the folder\'s views with: ' + answer.command);
});
for (const radio of document.querySelectorAll('input[name=view]')) {
  radio.addEventListener('change', () => {
    $('preview').src = '/stream.mjpeg?view=' + radio.value;
  });
}

const events = new EventSource('/api/events');
events.onmessage = (message) => show(JSON.parse(message.data));
events.onerror = () => {
  $('health').textContent = 'no connection';
  $('health').className = 'badge bad';
};
refreshHistory();
setInterval(refreshHistory, 1000);
