// The service worker: the page works offline once it has been loaded. Every file of the page
// (same origin, GET) is answered from the cache at once and fetched again in the background,
// so a new version is used from the next visit; the first visit caches what it loads, and the
// files listed below are fetched ahead so that the live mode and the demo open offline too.

const CACHE = 'hwfoc-web-v1';

/** Files cached at install, relative to this worker (one missing does not stop the install). */
const AHEAD = [
  './', './index.html', './style.css', './src/main.js', './src/hwfoc.js',
  './pkg/hwfoc_web.js', './pkg/hwfoc_web_bg.wasm',
  './src/files/chart.js', './src/files/csv.js', './src/files/index.js', './src/files/series.js', './src/files/summary.js', './src/files/view.js', './src/files/worker.js',
  './src/live/index.js', './src/live/alarms.js', './src/live/baud.js', './src/live/dashboard.js', './src/live/dom.js',
  './src/live/demo.js', './src/live/errors.js', './src/live/fleet.js', './src/live/limits.js',
  './src/live/ports.js', './src/live/recording.js', './src/live/slcan.js', './src/live/live.css',
  './src/live/demo.pcapng',
];

self.addEventListener('install', (event) => {
  event.waitUntil(caches.open(CACHE).then((cache) =>
    Promise.all(AHEAD.map((path) => cache.add(new URL(path, self.location).href).catch(() => {}))))
    .then(() => self.skipWaiting()));
});

self.addEventListener('activate', (event) => {
  event.waitUntil(caches.keys()
    .then((keys) => Promise.all(keys.filter((k) => k !== CACHE).map((k) => caches.delete(k))))
    .then(() => self.clients.claim()));
});

self.addEventListener('fetch', (event) => {
  const request = event.request;
  if (request.method !== 'GET' || new URL(request.url).origin !== self.location.origin) return;
  event.respondWith(caches.open(CACHE).then(async (cache) => {
    const cached = await cache.match(request, { ignoreSearch: true });
    const fresh = fetch(request).then((response) => {
      if (response.ok) cache.put(request, response.clone());
      return response;
    });
    if (cached) {
      event.waitUntil(fresh.catch(() => {}));
      return cached;
    }
    return fresh;
  }));
});
