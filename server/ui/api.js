// The dashboard's access to the REST API: the token (kept in sessionStorage), JSON calls,
// errors as {code, message}, and server-sent events read from a fetch stream (EventSource
// cannot send an Authorization header).

const MODE = document.querySelector('meta[name="surfmap-auth"]')?.content || 'none';
const KEY = 'surfmap-token';

export class ApiError extends Error {
  constructor(status, code, message) {
    super(`${code}: ${message}`);
    this.status = status;
    this.code = code;
  }
}

function headers(extra = {}) {
  const h = { ...extra };
  const t = sessionStorage.getItem(KEY);
  if (MODE === 'token' && t) h.Authorization = `Bearer ${t}`;
  return h;
}

async function raise(res) {
  let body = {};
  try { body = await res.json(); } catch { /* not JSON */ }
  if (res.status === 401 && MODE === 'token') sessionStorage.removeItem(KEY);
  throw new ApiError(res.status, body.code || `http_${res.status}`, body.message || res.statusText);
}

/** A JSON call; throws ApiError on a non-2xx answer. */
export async function api(path, { method = 'GET', body } = {}) {
  const init = { method, headers: headers(body ? { 'Content-Type': 'application/json' } : {}) };
  if (body !== undefined) init.body = JSON.stringify(body);
  const res = await fetch(path, init);
  if (!res.ok) await raise(res);
  return res.json();
}

/** The bytes of a GET; throws ApiError on a non-2xx answer. */
export async function bytes(path) {
  const res = await fetch(path, { headers: headers() });
  if (!res.ok) await raise(res);
  return res.arrayBuffer();
}

/** An artifact link the browser can follow (a download): a blob URL when a token is needed. */
export async function download(path, name) {
  const buf = await bytes(path);
  const a = document.createElement('a');
  a.href = URL.createObjectURL(new Blob([buf]));
  a.download = name;
  a.click();
  setTimeout(() => URL.revokeObjectURL(a.href), 10000);
}

/**
 * Reads `path` as server-sent events, calling onEvent(name, data) per event, until the
 * stream ends or `signal` aborts. Resolves when it ends.
 */
export async function events(path, onEvent, signal) {
  const res = await fetch(path, { headers: headers({ Accept: 'text/event-stream' }), signal });
  if (!res.ok) await raise(res);
  const reader = res.body.pipeThrough(new TextDecoderStream()).getReader();
  let buf = '';
  for (;;) {
    const { value, done } = await reader.read();
    if (done) return;
    buf += value.replace(/\r\n/g, '\n');
    let cut;
    while ((cut = buf.indexOf('\n\n')) >= 0) {
      const block = buf.slice(0, cut);
      buf = buf.slice(cut + 2);
      let name = 'message';
      const data = [];
      for (const line of block.split('\n')) {
        if (line.startsWith('event:')) name = line.slice(6).trim();
        else if (line.startsWith('data:')) data.push(line.slice(5).replace(/^ /, ''));
      }
      if (data.length) {
        try { onEvent(name, JSON.parse(data.join('\n'))); } catch (e) { console.warn('bad event', e); }
      }
    }
  }
}

/** Resolves once the API answers this browser: asks for a token when one is needed. */
export async function ensureAuth() {
  const out = document.getElementById('logout');
  if (MODE !== 'token') return;
  out.hidden = false;
  out.onclick = () => { sessionStorage.removeItem(KEY); location.reload(); };
  for (;;) {
    if (sessionStorage.getItem(KEY)) {
      try {
        await api('/v1/jobs?limit=1');
        return;
      } catch (e) {
        if (!(e instanceof ApiError) || e.status !== 401) throw e;
      }
    }
    await askToken(sessionStorage.getItem(KEY) === null ? '' : 'That token was refused.');
  }
}

function askToken(note) {
  return new Promise((resolve) => {
    const form = el('form', { id: 'login', className: 'login' },
      el('h2', {}, 'Sign in'),
      el('p', {}, 'This server needs an API token (kept for this browser tab only).'),
      el('p', { className: 'error' }, note || ''),
      el('input', { type: 'password', name: 'token', placeholder: 'API token', autocomplete: 'off', required: true }),
      el('button', { type: 'submit' }, 'Open'));
    form.onsubmit = (ev) => {
      ev.preventDefault();
      sessionStorage.setItem(KEY, form.token.value.trim());
      form.remove();
      resolve();
    };
    document.querySelector('main').prepend(form);
    form.token.focus();
  });
}

/** A DOM element: el('a', {href: x}, 'text', child...). */
export function el(tag, props = {}, ...children) {
  const e = Object.assign(document.createElement(tag), props);
  for (const c of children) if (c !== null && c !== undefined) e.append(c);
  return e;
}

export function fmtTime(ms) {
  return ms ? new Date(ms).toLocaleString() : '';
}

export function fmtDuration(ms) {
  if (ms === null || ms === undefined || ms < 0) return '';
  if (ms < 1000) return `${ms} ms`;
  if (ms < 60000) return `${(ms / 1000).toFixed(1)} s`;
  return `${Math.floor(ms / 60000)} min ${Math.round((ms % 60000) / 1000)} s`;
}

export const TERMINAL = new Set(['succeeded', 'failed', 'cancelled']);
