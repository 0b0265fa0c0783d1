// /ui/: the tenant's jobs, newest first, filtered by state and method; rows of unfinished jobs
// follow their SSE stream (a few at a time, the rest and new jobs on a periodic re-list).

import { api, ensureAuth, events, el, fmtTime, fmtDuration, TERMINAL } from '/ui/assets/api.js';

const MAX_STREAMS = 4;
const rows = new Map(); // id -> { tr, job }
const streams = new Map(); // id -> AbortController
let cursor = null;
let generation = 0; // bumped by a filter change: answers to older requests are dropped

const form = document.getElementById('filters');
const tbody = document.querySelector('#jobs tbody');
const status = document.getElementById('status');

function query(extra = {}) {
  const q = new URLSearchParams();
  for (const k of ['state', 'method']) if (form[k].value) q.set(k, form[k].value);
  for (const [k, v] of Object.entries(extra)) q.set(k, v);
  return q;
}

function took(j) {
  if (!j.started_at_ms) return '';
  return fmtDuration((j.finished_at_ms || Date.now()) - j.started_at_ms);
}

function progress(j) {
  const p = Math.round((j.state === 'succeeded' ? 1 : j.progress) * 100);
  return el('div', { className: 'bar', title: `${p}%` }, el('span', { style: `width:${p}%` }), el('em', {}, `${p}%`));
}

function actions(j) {
  const td = el('td', { className: 'actions' });
  if (!TERMINAL.has(j.state)) {
    const b = el('button', { className: 'cancel', textContent: 'cancel', disabled: j.cancel_requested });
    b.onclick = async () => {
      b.disabled = true;
      try { update(await api(j.links.cancel, { method: 'POST' })); } catch (e) { say(e.message, true); }
    };
    td.append(b);
  } else if (j.state !== 'succeeded') {
    const b = el('button', { className: 'retry', textContent: 'retry' });
    b.onclick = async () => {
      b.disabled = true;
      try {
        const n = await api('/v1/jobs', { method: 'POST', body: { meshes: j.meshes, spec: j.spec } });
        say(`retried as …${n.id.slice(-12)}`);
        await refresh();
      } catch (e) { say(e.message, true); b.disabled = false; }
    };
    td.append(b);
  }
  return td;
}

function render(j) {
  const tr = el('tr', { className: `job state-${j.state}` });
  tr.dataset.id = j.id;
  tr.dataset.state = j.state;
  tr.append(
    el('td', {}, el('a', { href: `/ui/jobs/${j.id}`, title: j.id }, el('code', {}, `…${j.id.slice(-12)}`))),
    el('td', { className: 'method' }, j.method),
    el('td', { className: 'state' }, el('span', { className: `pill ${j.state}` }, j.state),
      j.error ? el('small', { className: 'code', title: j.error.message }, ` ${j.error.code}`) : null),
    el('td', { className: 'stage' }, j.stage || ''),
    el('td', { className: 'progress' }, progress(j)),
    el('td', {}, fmtTime(j.created_at_ms)),
    el('td', {}, took(j)),
    actions(j));
  return tr;
}

function update(j) {
  const old = rows.get(j.id);
  const tr = render(j);
  if (old) old.tr.replaceWith(tr);
  rows.set(j.id, { tr, job: j });
  return tr;
}

function say(text, bad = false) {
  status.textContent = text;
  status.className = bad ? 'error' : '';
}

function follow() {
  for (const [id, { job }] of rows) {
    if (streams.size >= MAX_STREAMS) break;
    if (TERMINAL.has(job.state) || streams.has(id)) continue;
    const ctl = new AbortController();
    streams.set(id, ctl);
    events(`/v1/jobs/${id}/events`, (name, data) => { if (name === 'job' && rows.has(data.id)) update(data); }, ctl.signal)
      .catch((e) => { if (e.name !== 'AbortError') console.warn('events', id, e.message); })
      .finally(() => { streams.delete(id); follow(); });
  }
}

async function refresh() {
  const gen = generation;
  const page = await api(`/v1/jobs?${query({ limit: 50 })}`);
  if (gen !== generation) return;
  const keep = new Set(page.jobs.map((j) => j.id));
  for (const [id, r] of rows) {
    if (!keep.has(id) && !r.older) { r.tr.remove(); rows.delete(id); streams.get(id)?.abort(); }
  }
  let prev = null;
  for (const j of page.jobs) {
    const tr = update(j);
    if (prev) prev.after(tr); else tbody.prepend(tr);
    prev = tr;
  }
  if (cursor === null) cursor = page.next_cursor || null;
  document.getElementById('more').hidden = !cursor;
  document.getElementById('empty').hidden = rows.size > 0;
  follow();
}

async function older() {
  if (!cursor) return;
  const gen = generation;
  const page = await api(`/v1/jobs?${query({ limit: 50, cursor })}`);
  if (gen !== generation) return;
  for (const j of page.jobs) {
    const tr = update(j);
    rows.get(j.id).older = true;
    tbody.append(tr);
  }
  cursor = page.next_cursor || null;
  document.getElementById('more').hidden = !cursor;
  follow();
}

function reset() {
  generation += 1;
  for (const c of streams.values()) c.abort();
  streams.clear();
  rows.clear();
  tbody.replaceChildren();
  cursor = null;
  history.replaceState(null, '', `/ui/?${query()}`);
}

async function main() {
  const q = new URLSearchParams(location.search);
  for (const k of ['state', 'method']) form[k].value = q.get(k) || '';
  await ensureAuth();
  form.onchange = () => { reset(); refresh().catch((e) => say(e.message, true)); };
  document.getElementById('more').onclick = () => older().catch((e) => say(e.message, true));
  await refresh();
  // New jobs, and unfinished jobs beyond the streams followed, every few seconds.
  setInterval(() => refresh().catch((e) => say(e.message, true)), 3000);
}

main().catch((e) => say(e.message, true));
