// How the browser tests and benchmarks start Debian's chromium: headless, WebGL through ANGLE on
// Mesa's EGL, i.e. llvmpipe (the OpenGL the rest of gvio renders with off-screen, and what the
// viewer's targets name), or through SwiftShader, chromium's own software Vulkan
// (--gl swiftshader). Chromium falls back to SwiftShader silently where it cannot use Mesa, so the
// callers check rendererOf(page) against the one asked for.
export const glModes = {
  llvmpipe: ['--use-gl=angle', '--use-angle=gl-egl', '--ignore-gpu-blocklist'],
  swiftshader: ['--use-gl=angle', '--use-angle=swiftshader', '--enable-unsafe-swiftshader'],
};

export function chromiumArgs(gl = 'llvmpipe') {
  if (!glModes[gl]) throw new Error(`--gl ${gl}: one of ${Object.keys(glModes).join(', ')}`);
  return ['--no-sandbox', ...glModes[gl], '--allow-file-access-from-files'];
}

// The WebGL renderer the page gets, e.g. "ANGLE (Mesa/X.org, llvmpipe (LLVM 15.0.6 256 bits), ...".
export function rendererOf(page) {
  return page.evaluate(() => {
    const gl = document.createElement('canvas').getContext('webgl2');
    if (!gl) return 'no WebGL 2';
    const info = gl.getExtension('WEBGL_debug_renderer_info');
    return gl.getParameter(info ? info.UNMASKED_RENDERER_WEBGL : gl.RENDERER);
  });
}
