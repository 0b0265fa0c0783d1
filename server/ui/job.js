// /ui/jobs/{id}: the job (state, stage, progress live over SSE), its spec, timings per stage,
// metrics, error code, artifacts, and the 3D viewer once it has succeeded.

import { api, bytes, download, ensureAuth, events, el, fmtTime, fmtDuration, TERMINAL, ApiError } from '/ui/assets/api.js';

const id = decodeURIComponent(location.pathname.split('/').pop());
const status = document.getElementById('status');
const summary = document.getElementById('summary');
const details = document.getElementById('details');
let viewerLoaded = false;
window.surfmapViewer = null; // set once the viewer shows meshes (tests read it)

function say(text, bad = false) {
  status.textContent = text;
  status.className = bad ? 'error' : '';
}

function row(k, v) {
  return el('tr', {}, el('th', {}, k), el('td', {}, v ?? ''));
}

function renderSummary(j) {
  document.getElementById('job-id').textContent = j.id;
  const p = Math.round((j.state === 'succeeded' ? 1 : j.progress) * 100);
  const took = j.started_at_ms ? fmtDuration((j.finished_at_ms || Date.now()) - j.started_at_ms) : '';
  const actions = el('span');
  if (!TERMINAL.has(j.state)) {
    const b = el('button', { className: 'cancel', textContent: 'cancel', disabled: j.cancel_requested });
    b.onclick = async () => { b.disabled = true; try { renderSummary(await api(j.links.cancel, { method: 'POST' })); } catch (e) { say(e.message, true); } };
    actions.append(b);
  } else if (j.state !== 'succeeded') {
    const b = el('button', { className: 'retry', textContent: 'retry' });
    b.onclick = async () => {
      b.disabled = true;
      try { const n = await api('/v1/jobs', { method: 'POST', body: { meshes: j.meshes, spec: j.spec } }); location.href = `/ui/jobs/${n.id}`; } catch (e) { say(e.message, true); }
    };
    actions.append(b);
  }
  summary.replaceChildren(el('table', { className: 'kv' },
    row('state', el('span', { id: 'state', className: `pill ${j.state}` }, j.state)),
    row('stage', j.stage),
    row('progress', el('div', { className: 'bar' }, el('span', { style: `width:${p}%` }), el('em', {}, `${p}%`))),
    row('method', j.method),
    row('meshes', el('span', {}, ...j.meshes.map((m) => el('code', { title: m }, `${m.slice(0, 12)} `)))),
    row('attempts', `${j.attempts} of ${j.max_attempts}`),
    row('worker', j.worker),
    row('created', fmtTime(j.created_at_ms)),
    row('ran', took),
    j.error ? row('error', el('span', { className: 'error' }, el('code', { id: 'error-code' }, j.error.code), ` ${j.error.message}`)) : null,
    row('', actions)));
}

function timings(result) {
  const t = result?.timings_ms;
  const pairs = Array.isArray(t) ? t : t && typeof t === 'object' ? Object.entries(t) : [];
  if (!pairs.length) return null;
  const stages = pairs.filter(([name]) => name !== 'total');
  const total = stages.reduce((s, [, ms]) => s + ms, 0) || 1;
  return el('table', { className: 'timings' }, el('tr', {}, el('th', {}, 'stage'), el('th', {}, 'ms'), el('th', {})),
    ...pairs.map(([name, ms]) => el('tr', {}, el('td', {}, name), el('td', { className: 'num' }, ms.toFixed(1)),
      el('td', {}, name === 'total' ? null : el('div', { className: 'tbar', style: `width:${Math.max(1, 200 * ms / total)}px` })))));
}

function metrics(result) {
  if (!result) return null;
  const rows = [];
  for (const dir of ['source_to_target', 'target_to_source']) {
    const m = result[dir];
    if (!m || typeof m !== 'object') continue;
    for (const [k, v] of Object.entries(m)) if (typeof v === 'number') rows.push([dir, k, v]);
  }
  for (const [k, v] of Object.entries(result)) if (typeof v === 'number') rows.push(['', k, v]);
  return el('div', {},
    rows.length ? el('table', { className: 'metrics' }, ...rows.map(([d, k, v]) =>
      el('tr', {}, el('td', {}, d), el('th', {}, k), el('td', { className: 'num' }, Number.isInteger(v) ? String(v) : v.toPrecision(5))))) : null,
    el('details', {}, el('summary', {}, 'metrics.json'), el('pre', {}, JSON.stringify(result, null, 2))));
}

function artifacts(j) {
  if (!j.artifacts.length) return el('p', {}, 'None yet.');
  return el('ul', { className: 'artifacts' }, ...j.artifacts.map((a) => {
    const link = el('a', { href: a.url, className: 'artifact' }, a.name);
    link.onclick = (ev) => { ev.preventDefault(); download(a.url, a.name).catch((e) => say(e.message, true)); };
    return el('li', {}, link, el('small', {}, ` ${a.content_type}, ${(a.size / 1024).toFixed(1)} KiB`));
  }));
}

/** Pretty JSON with arrays of numbers (anchor rows, paths) kept on one line. */
function compactJson(v) {
  return JSON.stringify(v, null, 2).replace(/\[[\s\d.,eE+-]*\]/g, (m) => m.replace(/\s+/g, ' ').replace(/\[ /, '[').replace(/ \]/, ']'));
}

function renderDetails(j) {
  details.replaceChildren(...[
    el('h2', {}, 'Spec'), el('pre', { id: 'spec' }, compactJson(j.spec)),
    el('h2', {}, 'Timings per stage'), timings(j.result) || el('p', {}, j.state === 'succeeded' ? 'Not reported.' : 'When the job has succeeded.'),
    el('h2', {}, 'Metrics'), metrics(j.result) || el('p', {}, 'When the job has succeeded.'),
    el('h2', {}, 'Artifacts'), artifacts(j),
    geometryImages(j)].filter((x) => x));
}

/** A quad job's geometry and normal images (16-bit PNG), one row per mesh. */
function geometryImages(j) {
  const pngs = j.artifacts.filter((a) => /^(geometry|normal)_\d+_patch\d+\.png$/.test(a.name));
  if (!pngs.length) return null;
  const box = el('div', { id: 'geometry-images' });
  for (const a of pngs) {
    const img = el('img', { alt: a.name, title: a.name, className: 'gimg' });
    bytes(a.url).then((b) => { img.src = URL.createObjectURL(new Blob([b], { type: 'image/png' })); })
      .catch((e) => say(e.message, true));
    box.append(el('figure', {}, img, el('figcaption', {}, a.name.replace('.png', ''))));
  }
  return el('div', {}, el('h2', {}, 'Geometry images'), box);
}

async function showViewer(j) {
  if (viewerLoaded || j.state !== 'succeeded') return;
  const morph = j.artifacts.find((a) => a.name === 'morph.glb');
  if (!morph) return;
  viewerLoaded = true;
  const section = document.getElementById('viewer-section');
  section.hidden = false;
  const vs = document.getElementById('viewer-status');
  vs.textContent = 'loading…';
  const { Viewer } = await import('/ui/assets/viewer.js');
  const viewer = new Viewer(document.getElementById('viewer'));
  // A quad job's morph.glb holds mesh 0's remesh with the others' as morph targets: shown
  // side by side (its anchors count the input meshes' vertices, not the remeshes': not drawn).
  const quad = j.method === 'quad';
  const [src, tgt] = await Promise.all([bytes(morph.url), quad ? null : bytes(`/v1/meshes/${j.target}/glb`)]);
  const info = await viewer.load(src, tgt, quad ? {} : j.spec);
  if (quad) {
    document.querySelector('#viewer .tag.left').textContent = 'remesh of mesh 0';
    document.querySelector('#viewer .tag.right').textContent = `remesh of mesh ${j.meshes.length - 1}`;
  }
  vs.textContent = `${info.sourceVertices} source, ${info.targetVertices} target vertices`;
  document.getElementById('colouring').onchange = (e) => {
    viewer.colour(e.target.value);
    const s = viewer.distortionScale;
    vs.textContent = e.target.value === 'distortion' && s
      ? `area ratio: blue ×${(2 ** -s).toFixed(2)} … white ×1 … red ×${(2 ** s).toFixed(2)} (per source face)`
      : `${info.sourceVertices} source, ${info.targetVertices} target vertices`;
  };
  document.getElementById('show-anchors').onchange = (e) => viewer.markAnchors(e.target.checked);
  if (info.morph) {
    document.getElementById('morph-label').hidden = false;
    document.getElementById('morph').oninput = (e) => viewer.morph(Number(e.target.value));
  }
  window.surfmapViewer = viewer;
}

function show(j) {
  renderSummary(j);
  renderDetails(j);
  showViewer(j).catch((e) => { document.getElementById('viewer-status').textContent = e.message; console.error(e); });
}

async function main() {
  await ensureAuth();
  let j;
  try {
    j = await api(`/v1/jobs/${encodeURIComponent(id)}`);
  } catch (e) {
    if (e instanceof ApiError && e.status === 404) { say(`No job ${id} for this token (${e.code}).`, true); return; }
    throw e;
  }
  show(j);
  let last = j;
  while (!TERMINAL.has(last.state)) {
    try {
      await events(j.links.events, (name, data) => {
        if (name !== 'job') return;
        // Progress alone redraws the summary; the details once the state changes.
        if (data.state !== last.state) show(data); else renderSummary(data);
        last = data;
      });
    } catch (e) {
      if (e instanceof ApiError) throw e;
      await new Promise((r) => setTimeout(r, 1000)); // a dropped stream: follow it again
    }
    // The stream ends after a terminal state (or on a shutdown): read the job as it stands.
    const now = await api(`/v1/jobs/${encodeURIComponent(id)}`);
    if (now.state !== last.state || TERMINAL.has(now.state)) show(now);
    last = now;
  }
}

main().catch((e) => say(e.message, true));
