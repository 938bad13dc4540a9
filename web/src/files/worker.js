// Opens recordings off the page's thread: the page stays responsive while a large file is
// decoded. Each message {id, name, bytes} is answered {id, opened} (openFile's answer, its
// columns' buffers transferred) or {id, error}.

import * as api from '../hwfoc.js';

const ready = api.init();

self.onmessage = async ({ data: { id, name, bytes } }) => {
  try {
    await ready;
    const opened = api.openFile(name, bytes);
    const buffers = Object.values(opened.records.columns).map((c) => c.buffer);
    self.postMessage({ id, opened }, buffers);
  } catch (e) {
    self.postMessage({ id, error: `${name}: ${e?.message ?? e}` });
  }
};
