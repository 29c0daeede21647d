// The site's data files are scripts that call a global function (gvioScene, gvioChunk,
// gvioVoxels): a page opened from its folder (file://) may load scripts but not fetch files.

const pending = new Map(); // script name -> resolve

// Loads `src`, a script that calls one of the callbacks with `key`; resolves with its arguments.
export function loadDataScript(src, key) {
  return new Promise((resolve, reject) => {
    const script = document.createElement('script');
    pending.set(key, (...args) => {
      script.remove();
      resolve(args);
    });
    script.onerror = () => {
      pending.delete(key);
      script.remove();
      reject(new Error(`cannot load ${src}`));
    };
    script.src = src;
    document.head.appendChild(script);
  });
}

// Called by a data script: hands its arguments to whoever is waiting for `key`.
export function deliver(key, ...args) {
  const resolve = pending.get(key);
  if (!resolve) return;
  pending.delete(key);
  resolve(...args);
}

export function decodeBase64(text) {
  // A fresh buffer starting at offset 0, so typed arrays can view it at any aligned offset.
  if (typeof Uint8Array.fromBase64 === 'function') return Uint8Array.fromBase64(text);
  const binary = atob(text);
  const bytes = new Uint8Array(binary.length);
  for (let i = 0; i < binary.length; ++i) bytes[i] = binary.charCodeAt(i);
  return bytes;
}
