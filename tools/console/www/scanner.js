// scanner.js: the console's scanner display (docs/console.md): the gateway's 'B' message decoded,
// scan-converted with the geometry of platform/linux/sc_scanconv.c (the image fills the raster
// keeping its aspect; a curvilinear fan from its probe-face radius), colour Doppler over the grey
// image with the scanner's colour map (core/imaging/sc_doppler.c, sc_doppler_colour_rgb), the
// colour box outline, the pulsed-wave gate, and the overlay of platform/linux/sc_scan_overlay.c
// (depth scale in cm on the right edge, focus marker on the left edge, orientation marker on the
// side of scan line 0, readout of probe, depth, gain, dynamic range and TGC); a scrolling
// spectrum strip. Pure drawing: no DOM lookups besides the canvases it is given.

const HDR = 32, PARAMS = 48, DOPPLER = 32;
const HAS_PARAMS = 1, HAS_DOPPLER = 2, HAS_COLOUR = 4;

// Decode a 'B' message (a DataView and the bytes of the same buffer). Returns null when the
// message is shorter than its own header says (the page then keeps the previous frame).
export function decodeBscan(dv, u8) {
  if (dv.byteLength < HDR) return null;
  const f = {
    flags: dv.getUint8(1), frameNo: dv.getUint32(4, true), lines: dv.getUint16(8, true), samples: dv.getUint16(10, true),
    geometry: dv.getUint16(12, true), linkFlags: dv.getUint16(14, true), depthMm: dv.getFloat32(16, true),
    widthMm: dv.getFloat32(20, true), radiusMm: dv.getFloat32(24, true),
    veinPm: dv.getUint16(28, true), arteryPm: dv.getUint16(30, true),
    params: null, doppler: null, colour: null,
  };
  let p = HDR;
  const need = (n) => p + n <= dv.byteLength;
  if (f.lines === 0 || f.samples === 0 || !need(f.lines * f.samples)) return null;
  f.image = u8.subarray(p, p + f.lines * f.samples);
  p += f.lines * f.samples;
  if (f.flags & HAS_PARAMS) {
    if (!need(PARAMS)) return null;
    f.params = {
      gainDb: dv.getFloat32(p, true), dynRangeDb: dv.getFloat32(p + 4, true), focusMm: dv.getFloat32(p + 8, true),
      frequencyMhz: dv.getFloat32(p + 12, true), tgcDb: [...Array(8).keys()].map((i) => dv.getFloat32(p + 16 + 4 * i, true)),
    };
    p += PARAMS;
  }
  if (f.flags & HAS_DOPPLER) {
    if (!need(DOPPLER)) return null;
    const d = {
      lineLo: dv.getUint16(p, true), lineHi: dv.getUint16(p + 2, true), sampleLo: dv.getUint16(p + 4, true),
      sampleHi: dv.getUint16(p + 6, true), nyquistMmS: dv.getFloat32(p + 8, true), steerDeg: dv.getFloat32(p + 12, true),
      gateVelocityMmS: dv.getFloat32(p + 16, true), gateLine: dv.getUint16(p + 20, true),
      gateLo: dv.getUint16(p + 22, true), gateHi: dv.getUint16(p + 24, true), bins: dv.getUint16(p + 26, true),
      columns: [],
    };
    const n = dv.getUint16(p + 28, true);
    p += DOPPLER;
    if (d.lineHi > f.lines || d.lineLo >= d.lineHi || d.sampleHi > f.samples || d.sampleLo >= d.sampleHi ||
        d.bins > 128 || !need(n * (4 + d.bins))) return null;
    for (let i = 0; i < n; i++) {
      d.columns.push({ frameNo: dv.getUint32(p, true), bins: u8.subarray(p + 4, p + 4 + d.bins) });
      p += 4 + d.bins;
    }
    f.doppler = d;
    if (f.flags & HAS_COLOUR) {
      const n2 = (d.lineHi - d.lineLo) * (d.sampleHi - d.sampleLo);
      if (!need(n2)) return null;
      f.colour = new Int8Array(u8.buffer, u8.byteOffset + p, n2);
      p += n2;
    }
  }
  return f;
}

// The scanner's colour map (sc_doppler_colour_rgb): dark red -> red -> yellow toward the probe,
// dark blue -> blue -> cyan away.
export function colourRgb(v) {
  if (v === 0) return [0, 0, 0];
  const m = Math.abs(v);
  const main = m >= 64 ? 255 : 95 + Math.trunc((m * 160) / 64);
  const side = m > 80 ? Math.trunc(((m - 80) * 255) / 48) : 0;
  return v > 0 ? [main, side, 0] : [0, side, main];
}
const CMAP = [...Array(256).keys()].map((i) => colourRgb(i - 256 * (i >= 128)));

// The raster fit of sc_scanconv (build_linear, build_sector): mm per pixel s, and where the
// image frame's point (x lateral, z depth below the probe face, mm) lies in the raster.
export function rasterFit(f, W, H) {
  const d = f.depthMm > 0 ? f.depthMm : 1;
  if (f.geometry === 1) {
    const r0 = f.radiusMm > 0 ? f.radiusMm : 0, r1 = r0 + d;
    const half = ((f.widthMm > 0 ? f.widthMm : 60) * Math.PI) / 360;
    const wMm = 2 * r1 * Math.sin(half), z0 = r0 * Math.cos(half), hMm = r1 - z0;
    const s = Math.max(wMm / W, hMm / H);
    // apex frame: z from the apex = image z + r0; raster y = (zApex - z0) / s
    return { s, curved: true, r0, r1, half, d, top: z0 - r0,
      toPx: (x, z) => [W / 2 + x / s - 0.5, (z + r0 - z0) / s - 0.5] };
  }
  const wMm = f.widthMm > 0 ? f.widthMm : 1;
  const s = Math.max(wMm / W, d / H), x0 = (W - wMm / s) / 2;
  return { s, curved: false, wMm, d, x0, top: 0, toPx: (x, z) => [x0 + (x + wMm / 2) / s - 0.5, z / s - 0.5] };
}

// sc_overlay_edge_px: the raster point depthMm below the face on the right (or left) edge.
export function edgePx(f, fit, depthMm, right) {
  if (!(depthMm >= 0 && depthMm <= fit.d)) return null;
  if (fit.curved) {
    const r = fit.r0 + depthMm, a = right ? fit.half : -fit.half;
    return fit.toPx(r * Math.sin(a), r * Math.cos(a) - fit.r0);
  }
  return [right ? fit.x0 + fit.wMm / fit.s - 0.5 : fit.x0 - 0.5, depthMm / fit.s - 0.5];
}

// LUT: raster pixel -> line * samples + sample (or -1 outside the image), as sc_scanconv.
function buildLut(f, fit, W, H) {
  const lut = new Int32Array(W * H).fill(-1);
  for (let y = 0; y < H; y++) {
    for (let x = 0; x < W; x++) {
      let l, k;
      if (fit.curved) {
        const xm = (x + 0.5 - W / 2) * fit.s, zm = fit.r0 * Math.cos(fit.half) + (y + 0.5) * fit.s;
        const r = Math.hypot(xm, zm), a = Math.atan2(xm, zm);
        if (!(r >= fit.r0 && r < fit.r1 && a >= -fit.half && a < fit.half)) continue;
        l = Math.floor(((a + fit.half) / (2 * fit.half)) * f.lines);
        k = Math.floor(((r - fit.r0) / fit.d) * f.samples);
      } else {
        const xm = (x + 0.5 - fit.x0) * fit.s, zm = (y + 0.5) * fit.s;
        if (!(xm >= 0 && xm < fit.wMm && zm < fit.d)) continue;
        l = Math.floor((xm / fit.wMm) * f.lines);
        k = Math.floor((zm / fit.d) * f.samples);
      }
      if (l < f.lines && k < f.samples) lut[y * W + x] = l * f.samples + k;
    }
  }
  return lut;
}

export function createScanner(panel, spectrum) {
  const W = panel.width, H = panel.height;
  const image = document.createElement('canvas'); // grey + colour, transparent outside the image
  image.width = W; image.height = H;
  const ictx = image.getContext('2d'), pctx = panel.getContext('2d'), sctx = spectrum.getContext('2d');
  const idata = ictx.createImageData(W, H);
  let lut = null, lutKey = '', fit = null;
  let lastCol = null; // frame number of the newest spectrum column drawn
  const state = { overlay: null, colourPixels: 0, spectrumColumns: 0, frame: null };

  function draw(f) {
    const key = `${f.lines},${f.samples},${f.geometry},${f.depthMm},${f.widthMm},${f.radiusMm}`;
    if (key !== lutKey) { fit = rasterFit(f, W, H); lut = buildLut(f, fit, W, H); lutKey = key; }
    const px = idata.data, img = f.image, S = f.samples;
    const d = f.doppler, col = f.colour;
    const bs = d ? d.sampleHi - d.sampleLo : 0;
    // box outline about one raster pixel wide whatever the line and sample pitch
    const tl = Math.max(1, Math.ceil(f.lines / W)), ts = Math.max(1, Math.ceil((S * fit.s) / fit.d));
    let colourPixels = 0;
    for (let i = 0; i < W * H; i++) {
      const v = lut[i], o = i * 4;
      if (v < 0) { px[o] = px[o + 1] = px[o + 2] = px[o + 3] = 0; continue; }
      const g = img[v];
      px[o] = px[o + 1] = px[o + 2] = g; px[o + 3] = 255;
      if (!d) continue;
      const l = Math.trunc(v / S), k = v - l * S;
      if (l < d.lineLo || l >= d.lineHi || k < d.sampleLo || k >= d.sampleHi) continue;
      if (l - d.lineLo < tl || d.lineHi - 1 - l < tl || k - d.sampleLo < ts || d.sampleHi - 1 - k < ts) {
        px[o] = px[o + 1] = px[o + 2] = 190; // the colour box
        continue;
      }
      if (col) {
        const c = col[(l - d.lineLo) * bs + (k - d.sampleLo)];
        if (c !== 0) { const rgb = CMAP[c & 255]; px[o] = rgb[0]; px[o + 1] = rgb[1]; px[o + 2] = rgb[2]; colourPixels++; }
      }
    }
    ictx.putImageData(idata, 0, 0);
    pctx.fillStyle = '#000';
    pctx.fillRect(0, 0, W, H);
    pctx.drawImage(image, 0, 0);
    drawGate(f);
    state.overlay = drawOverlay(f);
    state.colourPixels = colourPixels;
    state.frame = f;
    drawSpectrum(f);
  }

  // the pulsed-wave gate: two short bars across the gate line at the gate's ends
  function drawGate(f) {
    const d = f.doppler;
    if (!d || d.bins === 0) return;
    const a = sampleToPx(f, d.gateLine + 0.5, d.gateLo), b = sampleToPx(f, d.gateLine + 0.5, d.gateHi);
    pctx.strokeStyle = '#fff'; pctx.lineWidth = 1;
    for (const [x, y] of [a, b]) { pctx.beginPath(); pctx.moveTo(x - 4, y + 0.5); pctx.lineTo(x + 5, y + 0.5); pctx.stroke(); }
  }
  // raster point of (fractional line, sample boundary)
  function sampleToPx(f, line, sample) {
    const zr = (sample / f.samples) * fit.d;
    if (fit.curved) {
      const a = -fit.half + (line / f.lines) * 2 * fit.half, r = fit.r0 + zr;
      return fit.toPx(r * Math.sin(a), r * Math.cos(a) - fit.r0);
    }
    return fit.toPx(-fit.wMm / 2 + (line / f.lines) * fit.wMm, zr);
  }

  function label(x, y, t) {
    pctx.font = '10px monospace';
    const w = pctx.measureText(t).width;
    pctx.fillStyle = '#000'; pctx.fillRect(x - 1, y - 1, w + 2, 11);
    pctx.fillStyle = '#fff'; pctx.fillText(t, x, y + 8);
  }

  // sc_overlay_draw_below with top 0, in the page's font
  function drawOverlay(f) {
    const o = { depthMm: f.depthMm, ticks: [], focus: null, marker: null, readout: [] };
    if (!(f.depthMm > 0)) return o;
    pctx.fillStyle = '#fff';
    for (let mm = 5; mm <= Math.floor(f.depthMm); mm += 5) {
      const e = edgePx(f, fit, mm, true);
      if (!e) continue;
      const major = mm % 10 === 0, len = major ? 10 : 5;
      const x = Math.round(e[0]), y = Math.round(e[1]);
      pctx.fillStyle = '#fff'; pctx.fillRect(x - len + 1, y, len, 1);
      o.ticks.push({ mm, x, y });
      if (major) {
        const t = String(mm / 10);
        label(x - len - 2 - 6 * t.length, y - 4, t);
      }
    }
    const p = f.params;
    if (p && p.focusMm > 0) {
      const e = edgePx(f, fit, p.focusMm, false);
      if (e) {
        const xi = Math.max(0, Math.round(e[0])), yi = Math.round(e[1]);
        pctx.fillStyle = '#fff';
        for (let i = 0; i < 5; i++) pctx.fillRect(xi + i, yi - (4 - i), 1, 2 * (4 - i) + 1);
        o.focus = { mm: p.focusMm, x: xi, y: yi };
      }
    }
    const e0 = edgePx(f, fit, 0, false);
    if (e0) { pctx.fillStyle = '#fff'; pctx.fillRect(Math.round(e0[0]) + 2, 2, 7, 7); o.marker = { x: Math.round(e0[0]) + 2, y: 2 }; }
    const probe = f.geometry === 1 ? 'C' : 'L';
    o.readout.push(p && p.frequencyMhz > 0 ? `${probe} ${p.frequencyMhz.toFixed(1)}MHZ D${(f.depthMm / 10).toFixed(1)}CM`
      : `${probe} D${(f.depthMm / 10).toFixed(1)}CM`);
    if (p && p.dynRangeDb > 0) {
      const sign = (v) => (Math.round(v) >= 0 ? '+' : '') + Math.round(v).toFixed(0);
      o.readout.push(`G${sign(p.gainDb)}DB DR${p.dynRangeDb.toFixed(0)}`);
      o.readout.push(`TGC ${p.tgcDb.map(sign).join(' ')}`);
    }
    const d = f.doppler;
    if (d) o.readout.push(`CF ${(d.nyquistMmS / 10).toFixed(1)}CM/S ST${sign0(d.steerDeg)}`);
    o.readout.forEach((t, i) => label(14, 3 + 10 * i, t));
    return o;
  }
  const sign0 = (v) => (Math.round(v) >= 0 ? '+' : '') + Math.round(v);

  // scrolling spectrum: one column per engine frame (2 px), newest at the right; velocity toward
  // the probe up, the baseline (0) and the scale (+-Nyquist) marked
  function drawSpectrum(f) {
    const d = f.doppler, SW = spectrum.width, SH = spectrum.height;
    if (!d || d.bins === 0 || d.columns.length === 0) return;
    const newest = d.columns[d.columns.length - 1].frameNo;
    if (lastCol !== null && ((newest - lastCol) | 0) < -256) lastCol = null; // another engine
    const fresh = d.columns.filter((c) => lastCol === null || ((c.frameNo - lastCol) | 0) > 0);
    if (fresh.length === 0) return;
    const dx = 2 * fresh.length;
    sctx.drawImage(spectrum, dx, 0, SW - dx - 40, SH, 0, 0, SW - dx - 40, SH);
    const x0 = SW - 40 - dx;
    for (const [j, c] of fresh.entries()) {
      for (let i = 0; i < d.bins; i++) {
        const v = c.bins[i];
        sctx.fillStyle = `rgb(${v},${v},${v})`;
        const y0 = SH - ((i + 1) * SH) / d.bins, y1 = SH - (i * SH) / d.bins;
        sctx.fillRect(x0 + 2 * j, Math.floor(y0), 2, Math.ceil(y1) - Math.floor(y0));
      }
      state.spectrumColumns++;
    }
    lastCol = newest;
    // scale strip on the right
    sctx.fillStyle = '#000'; sctx.fillRect(SW - 40, 0, 40, SH);
    sctx.fillStyle = '#777'; sctx.fillRect(0, SH / 2, SW - 40, 1);
    sctx.font = '10px monospace'; sctx.fillStyle = '#fff';
    const cm = (d.nyquistMmS / 10).toFixed(0);
    sctx.fillText(`+${cm}`, SW - 38, 9); sctx.fillText('0', SW - 38, SH / 2 + 4); sctx.fillText(`-${cm}`, SW - 38, SH - 2);
    sctx.fillText('cm/s', SW - 38, SH / 2 - 12);
    const gate = `PW gate ${d.gateVelocityMmS >= 0 ? '+' : ''}${(d.gateVelocityMmS / 10).toFixed(1)} cm/s`;
    sctx.fillStyle = '#000'; sctx.fillRect(0, 0, sctx.measureText(gate).width + 5, 12); // over the oldest columns
    sctx.fillStyle = '#fff'; sctx.fillText(gate, 3, 10);
    state.gateVelocityMmS = d.gateVelocityMmS;
    state.gateMaxMmS = Math.max(state.gateMaxMmS ?? 0, d.gateVelocityMmS);
  }

  // where the raster lies in the image frame (mm), for the image plane of the 3D view: the
  // raster covers W s x H s mm, centred laterally, its top row at z = fit.top
  function planeExtent() {
    if (!fit) return null;
    return { width: W * fit.s, height: H * fit.s, centreZ: fit.top + (H * fit.s) / 2 };
  }
  // image-frame point (mm) -> panel pixel
  function toPanel(x, z) { return fit ? fit.toPx(x, z) : null; }
  return { draw, image, state, planeExtent, toPanel };
}
