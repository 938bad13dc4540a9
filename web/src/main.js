// The page: loads the WebAssembly decoder, mounts the files mode, and the live mode (src/live/)
// the first time its tab is chosen.

import * as api from './hwfoc.js';
import { mountFiles } from './files/index.js';

const panels = { files: document.getElementById('files'), live: document.getElementById('live') };
let liveMounted = false;

function choose(tab) {
  for (const [name, panel] of Object.entries(panels)) panel.hidden = name !== tab;
  for (const b of document.querySelectorAll('[role=tab]')) {
    b.setAttribute('aria-selected', String(b.dataset.tab === tab));
  }
  if (tab === 'live' && !liveMounted) {
    liveMounted = true;
    import('./live/index.js')
      .then((m) => m.mountLive(panels.live, api))
      .catch((e) => {
        panels.live.textContent = `The live mode could not be loaded: ${e.message}`;
      });
  }
}

for (const b of document.querySelectorAll('[role=tab]')) {
  b.addEventListener('click', () => choose(b.dataset.tab));
}

await api.init();
mountFiles(panels.files, api);
document.body.dataset.ready = 'true';
