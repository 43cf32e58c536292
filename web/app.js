// The query page: lists the collections, sends a dropped or chosen mesh file
// or picture (or a clicked result's model id) to the gateway's JSON API and
// shows the ranked models as thumbnails. A gateway that wants a bearer token
// answers 401: the page then asks for it once and sends it with every call
// (thumbnails too, fetched rather than linked). No libraries: it must work
// offline.
'use strict';

const $ = (id) => document.getElementById(id);
const state = { queryLabel: null, token: sessionStorage.getItem('meshseek-token') || '' };
const PICTURE = /\.(png|jpe?g)$/i;

class Unauthorized extends Error {}

function authorized(options = {}) {
  if (!state.token) return options;
  return { ...options, headers: { ...(options.headers || {}), Authorization: `Bearer ${state.token}` } };
}

function askForToken(message) {
  $('token-form').hidden = false;
  $('token-message').textContent = message;
  $('token').focus();
}

function showError(message) {
  const box = $('error');
  box.textContent = message;
  box.hidden = !message;
}

async function api(url, options) {
  const response = await fetch(url, authorized(options));
  if (response.status === 401) {
    askForToken(state.token ? 'The gateway refused that token: enter it again.'
                            : 'This gateway wants a token: enter it to search.');
    throw new Unauthorized('the gateway wants a bearer token');
  }
  let body = null;
  try {
    body = await response.json();
  } catch (e) {
    throw new Error(`the gateway answered ${response.status} ${response.statusText}`);
  }
  if (!response.ok) throw new Error(body.error || `error ${response.status}`);
  return body;
}

async function loadCollections() {
  const select = $('collection');
  try {
    const { collections } = await api('/api/collections');
    select.replaceChildren();
    for (const c of collections) {
      const option = document.createElement('option');
      option.value = c.name;
      option.textContent = `${c.name} (${c.method}, ${c.indexed} models${c.built ? '' : ', not built'})`;
      option.disabled = !c.built;
      select.appendChild(option);
    }
    const wanted = new URLSearchParams(location.search).get('collection');
    const firstBuilt = collections.find((c) => c.built);
    if (wanted && collections.some((c) => c.name === wanted)) select.value = wanted;
    else if (firstBuilt) select.value = firstBuilt.name;
    if (!collections.length) showError('The coordinator has no collections yet: ingest and build one (meshseek ingest, meshseek build).');
  } catch (e) {
    if (!(e instanceof Unauthorized)) showError(`Cannot list the collections: ${e.message}`);
  }
}

function thumbnailUrl(collection, modelId) {
  return `/api/thumbnail?collection=${encodeURIComponent(collection)}&model_id=${encodeURIComponent(modelId)}`;
}

// Without a token the browser loads (and caches) thumbnails itself; with one
// it cannot send the header on an <img>, so they are fetched.
async function showThumbnail(img, url) {
  if (!state.token) {
    img.src = url;
    return;
  }
  const response = await fetch(url, authorized());
  if (!response.ok) return;
  img.onload = () => URL.revokeObjectURL(img.src);  // the image keeps its pixels
  img.src = URL.createObjectURL(await response.blob());
}

function render(answer, startedAt, picture) {
  const seconds = ((performance.now() - startedAt) / 1000).toFixed(2);
  const q = answer.query;
  $('query').hidden = false;
  const shown = $('query-thumbnail');
  if (q.thumbnail || picture) shown.src = q.thumbnail || picture;
  else showThumbnail(shown, thumbnailUrl(answer.collection, q.model_id));
  $('query-name').textContent = q.name;
  $('query-summary').textContent = q.summary || `model of ${answer.collection}`;
  const what = picture ? 'one silhouette' : `${q.features} local features`;
  $('query-status').textContent = `${what}; ${answer.results.length} results in ${seconds} s`;
  // A query by model knows its class: the result that is the model itself.
  const self = q.model_id ? answer.results.find((r) => r.model_id === q.model_id) : null;
  state.queryLabel = self && self.label ? self.label : null;
  const grid = $('results');
  grid.replaceChildren();
  for (const r of answer.results) {
    const card = document.createElement('figure');
    card.className = 'result';
    if (state.queryLabel && r.label === state.queryLabel) card.classList.add('hit');
    card.dataset.modelId = r.model_id;
    card.dataset.label = r.label;
    card.title = `search with ${r.model_id}`;
    const img = document.createElement('img');
    img.loading = 'lazy';
    img.alt = r.model_id;
    showThumbnail(img, thumbnailUrl(answer.collection, r.model_id));
    const caption = document.createElement('figcaption');
    const distance = r.distance === null ? 'no features' : r.distance.toFixed(4);
    caption.innerHTML = '<span class="rank"></span><div class="id"></div>' +
        '<div class="label"></div><div class="distance"></div>';
    caption.querySelector('.rank').textContent = `#${r.rank}`;
    caption.querySelector('.id').textContent = r.model_id;
    caption.querySelector('.label').textContent = r.label || '(no label)';
    caption.querySelector('.distance').textContent = `d = ${distance}`;
    card.append(img, caption);
    card.addEventListener('click', () => queryModel(r.model_id));
    grid.appendChild(card);
  }
  document.body.dataset.state = 'results';
}

async function run(request, picture) {
  showError('');
  document.body.dataset.state = 'searching';
  $('query-status').textContent = 'searching...';
  const startedAt = performance.now();
  try {
    render(await request(), startedAt, picture);
  } catch (e) {
    document.body.dataset.state = 'error';
    showError(e.message);
  }
}

// A PNG or JPEG is a picture (matched by its silhouette against the
// collection's LFD views); anything else is sent as a mesh file.
function queryFile(file) {
  const picture = file.type === 'image/png' || file.type === 'image/jpeg' || PICTURE.test(file.name);
  const form = new FormData();
  form.append('collection', $('collection').value);
  form.append('top_k', $('top-k').value);
  form.append(picture ? 'image' : 'mesh', file, file.name);
  const url = picture ? '/api/query_image' : '/api/query';
  run(() => api(url, { method: 'POST', body: form }), picture ? URL.createObjectURL(file) : null);
}

function queryModel(modelId) {
  const params = new URLSearchParams({
    collection: $('collection').value, model_id: modelId, top_k: $('top-k').value });
  run(() => api(`/api/query?${params}`));
  window.scrollTo({ top: 0, behavior: 'smooth' });
}

function setUpDropZone() {
  const zone = $('drop-zone');
  for (const type of ['dragenter', 'dragover']) {
    zone.addEventListener(type, (e) => { e.preventDefault(); zone.classList.add('dragging'); });
  }
  for (const type of ['dragleave', 'drop']) {
    zone.addEventListener(type, (e) => { e.preventDefault(); zone.classList.remove('dragging'); });
  }
  zone.addEventListener('drop', (e) => {
    if (e.dataTransfer.files.length) queryFile(e.dataTransfer.files[0]);
  });
  $('mesh-file').addEventListener('change', (e) => {
    if (e.target.files.length) queryFile(e.target.files[0]);
    e.target.value = '';  // choosing the same file again queries again
  });
}

function setUpTokenForm() {
  $('token-form').addEventListener('submit', (e) => {
    e.preventDefault();
    state.token = $('token').value.trim();
    sessionStorage.setItem('meshseek-token', state.token);
    $('token-form').hidden = true;
    showError('');
    loadCollections();
  });
}

setUpDropZone();
setUpTokenForm();
loadCollections();
