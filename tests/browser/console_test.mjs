// console_test.mjs: the console in a real browser (Debian's chromium driven by playwright-core)
// against sc-gateway and a running engine: sc-hostsim --live (the engine on the host simulator,
// paced to the wall clock, its deadline on the virtual clock; CAN over UDP because this host has
// no SocketCAN). Scenarios (argv[2]):
//   controls  switch case, method and gain from the page; the engine's status (its state stream)
//             reflects each; a refused command (answered, counted); a second client that can view
//             but not control without the pass phrase; zero deadline misses with clients connected
//   press     the tracker emulator presses the probe; a screenshot of the 3D view shows the vein
//             narrower than at rest
//   sessions  a short session recorded as a bundle (sc-hostsim --record-bundle) is listed on the
//             page with its score (sc-gateway --sessions); refused names and a broken bundle are
//             answered; the replay button replays it into the console (its frames, its case), and
//             the console is back on the live engine after it
//   doppler   the probe held on the skin: with colour on, the B-scan panel (a screenshot) shows
//             red/blue pixels inside the artery's section (cut from the live mesh), none anywhere
//             with colour off; the spectrum scrolls; after a depth change the overlay's depth
//             readout and scale match the engine's imaging depth; a curvilinear probe is drawn
//             as a fan from its probe-face radius
//   material  the Tissue panel: fat made softer with its slider (applied on release) and the
//             damping changed; the engine rebuilds the case and its MATERIAL record shows the new
//             values on the page; a command during the rebuild refused by the engine (counted), a
//             value outside the protocol refused by the gateway; "case materials" restores them
// Exit 0 pass, 1 fail, 77 skipped (chromium genuinely unavailable).
import { spawn, spawnSync } from 'node:child_process';
import { existsSync, mkdirSync, readFileSync, writeFileSync } from 'node:fs';
import { createServer } from 'node:net';
import { createSocket } from 'node:dgram';
import { createRequire } from 'node:module';
import path from 'node:path';

const scenario = process.argv[2] ?? 'controls';
const build = process.env.SC_BUILD_DIR;
const outDir = path.join(process.env.SC_OUT_DIR ?? path.join(build ?? '.', 'browser'), scenario);
const consoleDir = process.env.SC_CONSOLE_SRC; // tools/console (node_modules)
mkdirSync(outDir, { recursive: true });

const procs = []; // the programs started (declared first: fail() stops them)
function skip(why) { console.log(`SKIPPED: ${why}`); process.exit(77); }
async function fail(why) {
  console.log(`FAIL: ${why}`);
  cleanup();
  // the programs' own reports (the engine's summary comes at its exit)
  await Promise.race([Promise.all(procs.map((p) => stopped(p))), sleep(4000)]);
  for (const p of procs) console.log(`--- ${p.name}:\n${p.out.slice(-2500)}`);
  process.exit(1);
}
function ok(what) { console.log(`ok: ${what}`); }

const chromium = [process.env.CHROMIUM, '/usr/bin/chromium', '/usr/bin/chromium-browser'].find((p) => p && existsSync(p));
if (!chromium) skip('chromium not installed (apt-get install chromium; tools/install-deps.sh installs it)');
let playwright;
try {
  playwright = createRequire(path.join(consoleDir, 'package.json'))('playwright-core');
} catch (e) {
  await fail(`playwright-core not installed in ${consoleDir} (npm ci there; tools/install-deps.sh does it): ${e.message}`);
}
for (const f of ['platform/hostsim/sc-hostsim', 'tools/gateway/sc-gateway', 'tools/tracker_emu/sc-tracker-emu', 'console/index.html', 'cases/neck-ijv.scase']) {
  if (!existsSync(path.join(build, f))) await fail(`${f} not built in ${build}`);
}

const freeTcp = () => new Promise((res) => { const s = createServer(); s.listen(0, '127.0.0.1', () => { const p = s.address().port; s.close(() => res(p)); }); });
const freeUdp = () => new Promise((res) => { const s = createSocket('udp4'); s.bind(0, '127.0.0.1', () => { const p = s.address().port; s.close(() => res(p)); }); });
function sleep(ms) { return new Promise((r) => setTimeout(r, ms)); }

function start(name, args) {
  const p = spawn(args[0], args.slice(1), { stdio: ['ignore', 'pipe', 'pipe'] });
  p.out = '';
  p.stdout.on('data', (d) => { p.out += d; });
  p.stderr.on('data', (d) => { p.out += d; });
  p.name = name;
  procs.push(p);
  return p;
}
function cleanup() { for (const p of procs) if (p.exitCode === null) p.kill('SIGTERM'); }
function stopped(p) { return new Promise((res) => { if (p.exitCode !== null) res(); else p.on('exit', () => res()); }); }

async function waitFor(page, fn, arg, what, ms = 20000) {
  try {
    await page.waitForFunction(fn, arg, { timeout: ms, polling: 100 });
  } catch (e) {
    const st = await page.evaluate(() => JSON.stringify({ frame: window.sc?.frame, errors: window.sc?.errors })).catch(() => '?');
    await fail(`${what}: not within ${ms} ms (page state ${st})`);
  }
}

const [canPort, statePort, dlinkPort, httpPort] = [await freeUdp(), await freeUdp(), await freeUdp(), await freeTcp()];
const pass = 'instructor';
const GW_COLUMNS = 16; // tools/gateway/gw_bscan.h GW_BSCAN_COLUMNS
const GATE_X_MM = 4.6; // doppler: the probe's offset that puts neck-ijv's artery under the gate
// sessions: a recorded bundle (another case than the live engine's, 3 s of the press script, the
// trainee's call) and a broken one in the gateway's sessions folder
const sessDir = path.join(outDir, 'sessions');
const hostsim = path.join(build, 'platform/hostsim/sc-hostsim');
let bundle = null;
if (scenario === 'sessions') {
  mkdirSync(sessDir, { recursive: true });
  const rec = spawnSync(hostsim, ['--case', 'femoral', '--cases-dir', path.join(build, 'cases'), '--script', 'press',
    '--seconds', '3', '--every', '0', '--quiet', '--call', 'normal', '--out', path.join(outDir, 'record'),
    '--record-bundle', path.join(sessDir, 'press.scb')], { encoding: 'utf8' });
  if (rec.status !== 0) await fail(`sc-hostsim --record-bundle failed (${rec.status}): ${rec.stdout}${rec.stderr}`);
  writeFileSync(path.join(sessDir, 'broken.scb'), 'SCBUNDLE 1\nnot a bundle\n');
  const list = spawnSync(hostsim, ['--list-bundles', sessDir], { encoding: 'utf8' });
  bundle = JSON.parse(list.stdout).bundles.find((b) => b.file === 'press.scb');
  if (!bundle || bundle.error) await fail(`the recorded bundle is not listed by --list-bundles: ${list.stdout}`);
  ok(`recorded press.scb: ${bundle.case} ${bundle.method}, ${bundle.frames} frames, score ${bundle.score}/${bundle.score_max}`);
}
const engine = start('sc-hostsim', [path.join(build, 'platform/hostsim/sc-hostsim'), '--live', '--case', 'neck-ijv',
  '--cases-dir', path.join(build, 'cases'), '--can-udp', String(canPort), '--state-udp', `127.0.0.1:${statePort}`,
  '--dlink-udp', `127.0.0.1:${dlinkPort}`, '--seconds', '300', '--every', '0', '--quiet', '--out', path.join(outDir, 'engine')]);
const gateway = start('sc-gateway', [path.join(build, 'tools/gateway/sc-gateway'), '--port', String(httpPort),
  '--www', path.join(build, 'console'), '--state-port', String(statePort), '--dlink-port', String(dlinkPort),
  '--can-udp', `127.0.0.1:${canPort}`, '--cases-dir', path.join(build, 'cases'), '--pass', pass,
  ...(scenario === 'sessions' ? ['--sessions', sessDir, '--hostsim', hostsim] : [])]);
process.on('exit', cleanup);
// a playwright error (a timeout, a lost page) fails the test with the programs' reports
process.on('uncaughtException', (e) => { fail(`unexpected error: ${e.message.split('\n')[0]}`); });
process.on('unhandledRejection', (e) => { fail(`unexpected error: ${String(e?.message ?? e).split('\n')[0]}`); });
const url = `http://127.0.0.1:${httpPort}/`;

let browser;
try {
  browser = await playwright.chromium.launch({ executablePath: chromium, args: ['--no-sandbox', '--use-gl=swiftshader', '--enable-unsafe-swiftshader', '--ignore-gpu-blocklist'] });
} catch (e) {
  skip(`chromium at ${chromium} does not start: ${e.message.split('\n')[0]}`);
}
const page = await browser.newPage({ viewport: { width: 1100, height: 700 } });
page.on('pageerror', (e) => console.log(`page error: ${e.message}`));
for (let i = 0; i < 50; i++) {
  try { await page.goto(url); break; } catch (e) { await sleep(200); if (i === 49) await fail(`gateway at ${url} not answering: ${gateway.out}`); }
}
await waitFor(page, () => window.sc?.frame?.caseLoaded === 1 && window.sc.catalogue.length === 3 && window.sc.bscanFrames > 0,
  null, 'the page shows the running engine (state stream, catalogue, B-scan)');
ok(`page up: ${await page.evaluate(() => `${sc.records} records, ${sc.bscanFrames} B-scan frames, catalogue ${sc.catalogue.map((e) => e.name).join(' | ')}`)}`);
await page.fill('#pass', pass);
await page.click('#unlock');
await waitFor(page, () => window.sc.replies.some((m) => m.type === 'ack' && m.op === 'auth'), null, 'unlock with the pass phrase');

async function veinHeight(label) {
  // a screenshot of the 3D view in the measurement view; the vein is pure blue, unlit
  await page.evaluate(() => window.scMeasureView(4));
  await sleep(100);
  const png = await page.locator('#scene').screenshot({ path: path.join(outDir, `vein-${label}.png`) });
  return page.evaluate(async (b64) => {
    const img = await createImageBitmap(await (await fetch(`data:image/png;base64,${b64}`)).blob());
    const c = new OffscreenCanvas(img.width, img.height), x = c.getContext('2d');
    x.drawImage(img, 0, 0);
    const d = x.getImageData(0, 0, img.width, img.height).data;
    let top = -1, bottom = -1, px = 0;
    for (let y = 0; y < img.height; y++) {
      let row = 0;
      for (let xx = 0; xx < img.width; xx++) {
        const o = (y * img.width + xx) * 4;
        if (d[o + 2] > 150 && d[o] < 80 && d[o + 1] < 80) row++;
      }
      if (row > 0) { if (top < 0) top = y; bottom = y; px += row; }
    }
    return { height: top < 0 ? 0 : bottom - top + 1, pixels: px };
  }, png.toString('base64'));
}

if (scenario === 'sessions') {
  // the list: the recorded session with its score, the broken one with its reason
  await waitFor(page, () => window.sc.sessions.length === 2, null, 'the Sessions panel lists the two bundles');
  const row = await page.locator('#sessions tr[data-file="press.scb"]').innerText();
  const want = [bundle.case, bundle.method, String(bundle.frames), `${bundle.score}/${bundle.score_max}`];
  if (!want.every((w) => row.includes(w))) await fail(`the session's row "${row}" lacks one of ${JSON.stringify(want)}`);
  const bad = await page.locator('#sessions tr[data-file="broken.scb"]').innerText();
  if (!/refused/.test(bad)) await fail(`the broken bundle is not shown as refused: "${bad}"`);
  ok(`listed: "${row.replace(/\s+/g, ' ').trim()}"; "${bad.trim()}"`);
  // refused replays: names that leave the folder, an empty one, a broken bundle
  const e0 = await page.evaluate(() => window.sc.errors.length);
  for (const n of ['../x.scb', 'a/b.scb', '', 'broken.scb']) await page.evaluate((n) => window.scSend(JSON.stringify({ op: 'replay', name: n })), n);
  await waitFor(page, (e0) => window.sc.errors.length >= e0 + 4, e0, 'four refused replays answered');
  ok(`refused: ${await page.evaluate((e0) => window.sc.errors.slice(e0).map((e) => `${e.reason} (refused ${e.refused})`).join('; '), e0)}`);
  // the replay: frames from the bundle's engine (its frame counter restarts, its case), then live
  await waitFor(page, () => window.sc.frame.frames >= 30, null, 'the live engine past frame 30');
  const live = await page.evaluate(() => ({ frames: window.sc.frame.frames, crc: window.sc.frame.caseCrc }));
  if (live.crc === parseInt(bundle.case_id, 16)) await fail('the live engine runs the bundle\'s case: the test cannot tell them apart');
  await page.click('[data-testid="replay-press.scb"]');
  // a command right behind it (the same WebSocket, so the gateway sees it after the replay op) is
  // refused: it would go to the live engine, not the one shown
  await page.evaluate(() => window.scSend({ op: 'method', value: 'fem' }));
  await waitFor(page, () => window.sc.replay?.state === 'running', null, 'the replay started');
  await waitFor(page, (crc) => window.sc.frame.caseCrc === crc && window.sc.frame.frames > 0, parseInt(bundle.case_id, 16),
    'frames of the replay (the bundle\'s case) arrive', 30000);
  const during = await page.evaluate(() => ({ frames: window.sc.frame.frames, status: document.querySelector('#replay-status').textContent }));
  if (!(during.frames < live.frames)) await fail(`the frame counter did not restart: ${during.frames} after ${live.frames}`);
  if (!new RegExp(`^replaying press\\.scb \\(frame \\d+/${bundle.frames}\\)$`).test(during.status)) await fail(`status line "${during.status}"`);
  ok(`replaying: frame counter ${live.frames} (live) -> ${during.frames}, case 0x${(parseInt(bundle.case_id, 16) >>> 0).toString(16)}; "${during.status}"`);
  await waitFor(page, () => window.sc.errors.some((e) => /replay is running/.test(e.reason)), null, 'a command during the replay refused');
  await waitFor(page, () => window.sc.replay.state === 'ended', null, 'the replay ended', 60000);
  const end = await page.evaluate(() => window.sc.replay);
  if (!end.ok) await fail(`the replay failed (exit ${end.exit}): every image hash must match`);
  const maxFrame = end.frame; // the replay's newest frame the page saw
  if (!(maxFrame >= 0.9 * bundle.frames)) await fail(`the page saw the replay only up to frame ${maxFrame} of ${bundle.frames}`);
  await waitFor(page, (c) => window.sc.frame.caseCrc === c && window.sc.frame.frames > 0, live.crc, 'back on the live engine');
  ok(`replay ended (every image hash matched, last replay frame seen ${maxFrame}/${bundle.frames}); back on the live engine at frame ${await page.evaluate(() => window.sc.frame.frames)}`);
} else if (scenario === 'doppler') {
  await waitFor(page, () => window.sc.surf && window.sc.surf.count >= 2, null, 'surfaces of the case');
  // the probe on the skin 4.6 mm beside the default point (the artery under the pulsed-wave
  // gate, which sits mid-image at 20 mm), light contact, held, its beam tilted 20 deg
  // about the aperture (x) axis: the vessels cross the image plane, and a beam square to them
  // sees no velocity along it (cos 90 deg), as on a scanner
  const csv = path.join(outDir, 'hold.csv');
  const tilt = (20 * Math.PI) / 180, qw = Math.cos((Math.PI + tilt) / 2), qx = Math.sin((Math.PI + tilt) / 2);
  const rows = [[0, 30], [0.5, 30], [1.5, 0], [2.5, -1], [120, -1]];
  writeFileSync(csv, rows.map(([t, z]) => `${t},${GATE_X_MM},0,${z},${qw.toFixed(5)},${qx.toFixed(5)},0,0,${(Math.max(0, -z) * 0.5).toFixed(2)}`).join('\n') + '\n');
  const emu = start('sc-tracker-emu', [path.join(build, 'tools/tracker_emu/sc-tracker-emu'), '--csv', csv, '--duration-s', '120', '--rate-hz', '100',
    '--udp', `127.0.0.1:${canPort}`]);
  // (100 poses a second, the tracker's rate: the engine may run at a fraction of real time on
  // this loaded host, and its CAN receive mailboxes (platform/linux/sc_can_rxmb.h) put the
  // page's commands before the poses that wait and keep only the newest of those)
  // colour on from the page's Colour Doppler panel (every field is sent with the slider)
  await page.locator('#colour').setChecked(true);
  await page.locator('#prf').fill('3000');
  await waitFor(page, () => window.sc.frame.contact === 1 && window.sc.scanner?.frame?.colour && window.sc.scanner.frame.doppler.nyquistMmS > 0,
    null, 'frames with colour in contact', 40000);
  // (the surfaces' triangles arrive in rounds: slower on a loaded host)
  await waitFor(page, () => window.scSectionPx(5) !== null, null, 'the artery crosses the image plane', 60000);
  // red/blue pixels of the panel (screenshots, what the user sees) inside a box
  async function colourPixels(label, box) {
    const png = await page.locator('#bscan').screenshot({ path: path.join(outDir, `bscan-${label}.png`) });
    return page.evaluate(async ([b64, box]) => {
      const img = await createImageBitmap(await (await fetch(`data:image/png;base64,${b64}`)).blob());
      const c = new OffscreenCanvas(img.width, img.height), x = c.getContext('2d');
      x.drawImage(img, 0, 0);
      const d = x.getImageData(0, 0, img.width, img.height).data;
      let red = 0, blue = 0, all = 0;
      for (let y = 0; y < img.height; y++) for (let xx = 0; xx < img.width; xx++) {
        const o = (y * img.width + xx) * 4, r = d[o], g = d[o + 1], b = d[o + 2];
        const isRed = r >= 90 && r - b >= 60 && r - g >= 0, isBlue = b >= 90 && b - r >= 60 && b - g >= 0;
        if (!isRed && !isBlue) continue;
        all++;
        if (box && xx >= box.x0 && xx <= box.x1 && y >= box.y0 && y <= box.y1) { red += isRed; blue += isBlue; }
      }
      return { red, blue, all, w: img.width, h: img.height };
    }, [png.toString('base64'), box]);
  }
  let best = null;
  for (let i = 0; i < 8 && !(best && best.red + best.blue >= 30); i++) {
    const box = await page.evaluate(() => window.scSectionPx(5));
    const n = await colourPixels(`colour-on-${i}`, box);
    if (!best || n.red + n.blue > best.red + best.blue) best = { ...n, box };
    await sleep(250);
  }
  const bx = best.box;
  ok(`colour on: ${best.red} red + ${best.blue} blue px inside the artery's section (panel px ${bx.x0.toFixed(0)}..${bx.x1.toFixed(0)} x ${bx.y0.toFixed(0)}..${bx.y1.toFixed(0)}; ` +
     `${bx.mm.x0.toFixed(1)}..${bx.mm.x1.toFixed(1)} mm lateral, ${bx.mm.z0.toFixed(1)}..${bx.mm.z1.toFixed(1)} mm deep), ${best.all} colour px in the panel`);
  if (Math.abs(best.w - 290) > 1 || Math.abs(best.h - 290) > 1) await fail(`the panel screenshot is ${best.w}x${best.h}, want 290x290 (the canvas unscaled)`);
  if (!(best.red + best.blue >= 30)) await fail(`too few colour pixels inside the artery with colour on: ${best.red + best.blue}`);
  await page.locator('#scene').screenshot({ path: path.join(outDir, 'scene-colour.png') }); // the image plane, for a reader
  // the spectrum scrolls (one column per engine frame) and the gate reads the flow model
  const sp = () => page.evaluate(() => [window.sc.scanner.spectrumColumns, window.sc.scanner.frame.frameNo]);
  await page.evaluate(() => { window.sc.scanner.gateMaxMmS = 0; });
  const [c0, f0] = await sp();
  await sleep(2000);
  const [c1, f1] = await sp();
  if (!(c1 - c0 >= 2 && c1 - c0 >= 0.5 * (f1 - f0) && c1 - c0 <= f1 - f0 + GW_COLUMNS))
    await fail(`the spectrum scrolled ${c1 - c0} columns while the display link advanced ${f1 - f0} frames`);
  const sz = await page.evaluate(() => { const f = window.sc.scanner.frame, d = f.doppler;
    return `${window.sc.bscanBytes} B (${f.lines}x${f.samples} image, box ${d.lineHi - d.lineLo}x${d.sampleHi - d.sampleLo}, ${d.columns.length} columns of ${d.bins} bins)`; });
  ok(`B-scan message with colour: ${sz}`);
  const gateMax = await page.evaluate(() => window.sc.scanner.gateMaxMmS);
  await page.locator('#spectrum').screenshot({ path: path.join(outDir, 'spectrum.png') });
  // the gate in the artery: flow toward the probe (red, as the artery's colour)
  if (!(gateMax > 0)) await fail(`the pulsed-wave gate saw no flow toward the probe (max ${gateMax} mm/s)`);
  ok(`spectrum: ${c1 - c0} columns while the display link advanced ${f1 - f0} frames (one column per frame, ${GW_COLUMNS} kept by the gateway); gate velocity up to ${gateMax.toFixed(0)} mm/s toward the probe`);
  // colour off: no colour pixel anywhere in the panel
  await page.locator('#colour').setChecked(false);
  await waitFor(page, () => !window.sc.scanner.frame.colour, null, 'frames without colour');
  // one frame can come without colour before the command has landed (the page sends it 150 ms
  // after the click; a frame whose Doppler record the loaded host's UDP dropped has none): colour
  // is off when three screenshots in a row, 300 ms apart, show none, within 20 of them (a check.sh
  // run with both cores busy failed here with 3,015 colour pixels 300 ms after the first such frame)
  let off = null, clean = 0;
  for (let i = 0; i < 20 && clean < 3; i++) {
    await sleep(300);
    off = await colourPixels(clean === 0 ? 'colour-off' : `colour-off-${clean}`, null);
    clean = off.all === 0 ? clean + 1 : 0;
  }
  if (clean < 3) await fail(`colour pixels in the panel with colour off: no three clean screenshots in a row of 20 (the last had ${off.all})`);
  ok('colour off: no red or blue pixel in the panel');
  // depth: the overlay's readout and scale follow the engine's imaging depth
  await page.locator('#depth').fill('30');
  await waitFor(page, () => Math.abs(window.sc.frame.depthMm - 30) < 0.01 && Math.abs(window.sc.scanner.frame.depthMm - 30) < 0.01,
    null, 'the engine images 30 mm deep');
  await sleep(200);
  // the image's last row (the scan-converted image, transparent outside it) in the middle column
  const ov = await page.evaluate(() => {
    const c = window.scScannerImage(), x = c.getContext('2d'), col = x.getImageData(c.width >> 1, 0, 1, c.height).data;
    let bottom = -1;
    for (let y = 0; y < c.height; y++) if (col[4 * y + 3] > 0) bottom = y;
    return { o: window.sc.scanner.overlay, engine: window.sc.frame.depthMm, bottom };
  });
  const want = `D${(ov.engine / 10).toFixed(1)}CM`;
  if (!ov.o.readout[0].includes(want)) await fail(`overlay readout "${ov.o.readout[0]}" lacks ${want}`);
  const last = ov.o.ticks[ov.o.ticks.length - 1];
  if (last.mm !== 30 || Math.abs(last.y - ov.bottom) > 1) await fail(`the depth scale's last tick: ${JSON.stringify(last)}, want 30 mm at the image's bottom row ${ov.bottom}`);
  ok(`overlay: "${ov.o.readout.join(' | ')}"; engine depth ${ov.engine} mm; scale ${ov.o.ticks.length} ticks, 3 cm at y ${last.y} (image's last row ${ov.bottom}); focus ${JSON.stringify(ov.o.focus)}`);
  await page.locator('#bscan').screenshot({ path: path.join(outDir, 'bscan-depth30.png') });
  // curvilinear: the fan (its probe-face radius) leaves the panel's top corners black
  await page.locator('#geometry').selectOption('curvilinear');
  await waitFor(page, () => window.sc.scanner.frame.geometry === 1, null, 'curvilinear frames');
  await sleep(300);
  const fan = await page.evaluate(() => {
    const f = window.sc.scanner.frame, c = document.querySelector('#bscan').getContext('2d');
    const at = (x, y) => c.getImageData(x, y, 1, 1).data;
    // each depth tick on the fan's right edge: the image inside it, nothing outside it
    const img = window.scScannerImage().getContext('2d'), alpha = (x, y) => img.getImageData(x, y, 1, 1).data[3];
    const ticks = window.sc.scanner.overlay.ticks;
    const offEdge = ticks.filter((t) => t.x + 3 < 290 && !(alpha(t.x - 3, t.y) > 0 && alpha(t.x + 3, t.y) === 0));
    return { radius: f.radiusMm, sector: f.widthMm, corner: [...at(1, 60)], last: ticks.at(-1), ticks: ticks.length, offEdge };
  });
  await page.locator('#bscan').screenshot({ path: path.join(outDir, 'bscan-curvilinear.png') });
  if (!(fan.radius > 0)) await fail(`curvilinear frames carry no probe-face radius: ${JSON.stringify(fan)}`);
  if (fan.corner[0] + fan.corner[1] + fan.corner[2] !== 0) await fail(`the panel's top left corner is not black outside the fan: ${fan.corner}`);
  if (fan.offEdge.length > 0 || fan.ticks < 6) await fail(`depth ticks off the fan's edge: ${JSON.stringify(fan.offEdge)} (${fan.ticks} ticks)`);
  ok(`curvilinear: radius ${fan.radius} mm, sector ${fan.sector} deg; ${fan.ticks} depth ticks on the fan's right edge, the last ${JSON.stringify(fan.last)}`);
  await page.locator('#geometry').selectOption('linear');
  emu.kill('SIGTERM');
  await stopped(emu);
} else if (scenario === 'material') {
  await waitFor(page, () => window.sc.material && window.sc.material.labels.fat, null, 'the Tissue panel shows the engine\'s materials');
  const m0 = await page.evaluate(() => window.sc.material);
  if (Math.abs(m0.labels.fat.eKpa - 3.5) > 0.01 || m0.mask !== 0) await fail(`the case's fat is not shown: ${JSON.stringify(m0.labels.fat)}, mask ${m0.mask}`);
  ok(`engine's fat E ${m0.labels.fat.eKpa} kPa, nu ${m0.labels.fat.nu.toFixed(3)}, damping ${m0.dampingS.toFixed(3)} s, ${m0.cgIterations} CG iterations`);
  // the fat slider to 0.7 kPa (log10 -0.15, on the slider's 0.01 grid), released: CmdMaterial,
  // the rebuild, the record
  const applied0 = await page.evaluate(() => window.sc.frame.commandsApplied);
  await page.locator('[data-testid=mat-e-fat]').fill('-0.15');
  await waitFor(page, (r0) => window.sc.material.rebuilds > r0 && Math.abs(window.sc.material.labels.fat.eKpa - 0.7) < 0.01 &&
    window.sc.material.labels.fat.overridden === 1, m0.rebuilds, 'the engine rebuilt the case with fat at 0.7 kPa', 30000);
  const shown = await page.locator('[data-testid=mat-e-fat-v]').innerText();
  const status = await page.locator('[data-testid=tissue-status]').innerText();
  if (!/^0\.70*$/.test(shown) || !/fat/.test(status)) await fail(`the panel shows "${shown}" kPa, "${status}"`);
  if (!(await page.evaluate(() => window.sc.frame.commandsApplied) > applied0)) await fail('the engine did not count the command applied');
  ok(`fat slider released at 0.7 kPa: engine rebuilt (${await page.evaluate(() => window.sc.material.rebuilds)} rebuilds); panel "${shown} kPa", "${status}"`);
  // damping 0.2 s from its slider (sent with the last label moved, fat, as shown)
  await page.locator('[data-testid=mat-damping]').fill('0.2');
  await waitFor(page, () => Math.abs(window.sc.material.dampingS - 0.2) < 0.002 && window.sc.material.simOverride &&
    Math.abs(window.sc.material.labels.fat.eKpa - 0.7) < 0.01, null, 'the engine runs with damping 0.2 s', 30000);
  await page.locator('#tissue-panel').screenshot({ path: path.join(outDir, 'tissue-panel.png') });
  ok(`damping slider: engine's damping ${await page.evaluate(() => window.sc.material.dampingS.toFixed(3))} s, fat still 0.7 kPa`);
  // two commands back to back: the second arrives while the first one's rebuild runs (refused
  // by the engine, counted); a Poisson ratio outside the protocol is refused by the gateway
  const ref0 = await page.evaluate(() => window.sc.material.refused);
  const e0 = await page.evaluate(() => window.sc.errors.length);
  await page.evaluate(() => {
    const m = { op: 'material', label: 'muscle', e_kpa: 30, nu: 0.45, damping_s: 0.2, cg_iterations: 10, corotated: 0 };
    window.scSend(m); window.scSend({ ...m, label: 'nerve', e_kpa: 80 });
    window.scSend({ ...m, nu: 0.6 });
  });
  await waitFor(page, (e0) => window.sc.errors.length > e0, e0, 'nu 0.6 refused by the gateway');
  await waitFor(page, (ref0) => window.sc.material.refused > ref0 && Math.abs(window.sc.material.labels.muscle.eKpa - 30) < 0.05,
    ref0, 'muscle applied, the command during its rebuild refused and counted', 30000);
  const mm = await page.evaluate(() => window.sc.material);
  if (mm.labels.nerve.overridden) await fail('the command sent during the rebuild was applied');
  ok(`busy: muscle 30 kPa applied, the nerve command during its rebuild refused (${mm.refused} refused); gateway: ${await page.evaluate((e0) => window.sc.errors[e0].reason.slice(0, 60), e0)}`);
  // a client without the pass phrase sees the materials but cannot change them
  const viewer = await browser.newPage({ viewport: { width: 900, height: 600 } });
  await viewer.goto(url);
  await waitFor(viewer, () => window.sc?.material?.labels?.muscle && Math.abs(window.sc.material.labels.muscle.eKpa - 30) < 0.05,
    null, 'a second client sees the engine\'s materials');
  await viewer.locator('[data-testid=mat-e-skin]').fill('1');
  await waitFor(viewer, () => window.sc.errors.some((e) => e.op === 'material' && /locked/.test(e.reason)), null,
    'the locked client\'s material command refused');
  await viewer.close();
  ok('a client without the pass phrase: materials shown, its material command refused (controls locked)');
  // "case materials": CmdReset tissue restores the case's own
  await page.click('[data-testid=mat-restore]');
  await waitFor(page, () => window.sc.material.mask === 0 && !window.sc.material.simOverride &&
    Math.abs(window.sc.material.labels.fat.eKpa - 3.5) < 0.01 && Math.abs(window.sc.material.dampingS - 0.1) < 1e-4,
  null, 'the case\'s own materials restored', 30000);
  ok(`restored: fat ${await page.evaluate(() => window.sc.material.labels.fat.eKpa)} kPa, "${await page.locator('[data-testid=tissue-status]').innerText()}"`);
} else if (scenario === 'press') {
  await waitFor(page, () => window.sc.surf && window.sc.surf.count >= 2, null, 'surfaces of the case');
  await sleep(2500); // every triangle and vertex round has arrived
  const rest = await veinHeight('rest');
  ok(`vein at rest: ${rest.height} px high, ${rest.pixels} px`);
  if (rest.height < 20) await fail(`the vein is not visible at rest (${rest.height} px)`);
  // the probe over the default point (tracker frame, beam down; the skin at z = 0): from 30 mm
  // above to 2 mm above in 1 s, then slowly (2 mm/s) to 10 mm below the skin, held 6 s, lifted.
  // Slowly, because the sanitizer build on a loaded host (chromium's software GL beside it) may
  // run the engine at a fraction of real time: a fast press would reach it as a jump of the
  // probe into the tissue in one frame instead of a press
  const csv = path.join(outDir, 'press.csv');
  const rows = [[0, 30], [0.5, 30], [1.5, 2], [7.5, -10], [13.5, -10], [14.5, 30]];
  writeFileSync(csv, rows.map(([t, z]) => `${t},0,0,${z},0,1,0,0,${(Math.max(0, -z) * 0.5).toFixed(2)}`).join('\n') + '\n');
  const emu = start('sc-tracker-emu', [path.join(build, 'tools/tracker_emu/sc-tracker-emu'), '--csv', csv,
    '--udp', `127.0.0.1:${canPort}`]);
  await waitFor(page, () => window.sc.frame.contact === 1 && window.sc.frame.vein >= 0 && window.sc.frame.vein < 0.3, null,
    'the engine reports the vein compressed (area ratio < 0.3)', 30000);
  await sleep(1000); // the press held: the surfaces' vertex rounds (about 130 ms each) catch up
  const pressed = await veinHeight('pressed');
  const ratio = await page.evaluate(() => window.sc.frame.vein);
  ok(`vein pressed: ${pressed.height} px high, ${pressed.pixels} px (engine's vein area ratio ${ratio.toFixed(3)})`);
  if (!(pressed.height < 0.7 * rest.height)) await fail(`the vein is not visibly narrower: ${pressed.height} px vs ${rest.height} px at rest`);
  ok(`the vein in the 3D view is ${(100 * (1 - pressed.height / rest.height)).toFixed(0)} % narrower (screenshots in ${outDir})`);
  await stopped(emu);
  // the exam's assessment: the trainee's call from the page reaches the engine (CmdAssessment)
  // and comes back scored in the stream's ASSESSMENT record
  await page.click('[data-call=normal]');
  await waitFor(page, () => window.sc.assessment && window.sc.assessment.call === 'normal', null,
    'the assessment shows the call');
  const a = await page.evaluate(() => window.sc.assessment);
  if (!((a.met >> 4) & 1)) await fail(`the correct call "normal" on a normal case did not score (criteria 0x${a.met.toString(16)})`);
  if (!(a.vessels[0].inView > 0 && a.vessels[0].min < 0.3)) await fail(`the assessment missed the press: vein ${JSON.stringify(a.vessels[0])}`);
  if (a.revision !== 1 || a.points.length !== 6 || a.arteryPunctures !== 0)
    await fail(`the page did not read the record's revision 1 (criterion 5, punctures): ${JSON.stringify(a)}`);
  ok(`assessment: score ${a.score}/${a.scoreMax}, vein min ratio ${a.vessels[0].min.toFixed(3)}, call ${a.call} scored`);
  await page.evaluate(() => window.scNormalView());
} else {
  // switch the case
  const applied0 = await page.evaluate(() => window.sc.frame.commandsApplied);
  await page.click('[data-testid=case-1]');
  await waitFor(page, () => window.sc.frame.caseId === 1 && window.sc.frame.caseLoaded === 1 && !window.sc.frame.switching, null, 'case 1 running', 30000);
  await waitFor(page, () => window.sc.surf && window.sc.surf.name === window.sc.catalogue[1].name, null, 'the view shows case 1');
  ok(`case switched to #1 (${await page.evaluate(() => window.sc.surf.name)})`);
  // method
  await page.click('[data-testid=method-fem]');
  await waitFor(page, () => window.sc.frame.method === 'fem', null, 'method FEM');
  ok('method switched to FEM');
  // gain
  await page.locator('#gain').fill('12');
  await waitFor(page, () => Math.abs(window.sc.frame.gainDb - 12) < 0.01, null, 'gain 12 dB');
  ok('gain set to 12 dB');
  const applied1 = await page.evaluate(() => window.sc.frame.commandsApplied);
  if (applied1 - applied0 < 3) await fail(`the engine counted ${applied1 - applied0} applied commands, want >= 3`);
  ok(`engine applied ${applied1 - applied0} commands`);
  // a refused command: answered and counted, the engine untouched
  await page.evaluate(() => window.scSend('{"op":"method","value":"magic"}'));
  await page.evaluate(() => window.scSend('{"op":"imaging","depth_mm":5000,"gain_db":0,"dyn_range_db":60,"tgc_db_per_cm":0,"geometry":"linear"}'));
  await waitFor(page, () => window.sc.errors.length >= 2, null, 'two refusals answered');
  const errs = await page.evaluate(() => window.sc.errors.map((e) => `${e.reason} (refused ${e.refused})`));
  ok(`refused: ${errs.join('; ')}`);
  await sleep(300);
  if (await page.evaluate(() => window.sc.frame.method) !== 'fem') await fail('a refused command changed the method');
  // a second client: views at once, cannot control without the pass phrase
  const page2 = await browser.newPage({ viewport: { width: 900, height: 600 } });
  await page2.goto(url);
  await waitFor(page2, () => window.sc?.frame?.caseId === 1 && window.sc.bscanFrames > 2 && window.sc.catalogue.length === 3, null, 'second client sees the engine');
  await page2.click('[data-testid=case-0]');
  await waitFor(page2, () => window.sc.errors.some((e) => /locked/.test(e.reason)), null, 'second client refused without the pass phrase');
  await sleep(500);
  if (await page.evaluate(() => window.sc.frame.caseId) !== 1) await fail('the locked client switched the case');
  // each client's own frame count goes on (compared with its own earlier value: the two pages'
  // streams need not be at the same record, and a loaded ASan engine can take 0.5 s for a frame)
  const [f1, g1] = await Promise.all([page, page2].map((p) => p.evaluate(() => window.sc.frame.frames)));
  await waitFor(page, (f) => window.sc.frame.frames > f, f1, 'the first client stopped updating while the second was connected');
  await waitFor(page2, (f) => window.sc.frame.frames > f, g1, 'the second client stopped updating');
  const b2 = await page2.evaluate(() => window.sc.bscanFrames);
  ok(`second client: viewing (${b2} B-scan frames), its command refused (controls locked); both clients updated`);
  await page2.close();
}
const misses = await page.evaluate(() => window.sc.frame.misses);
await browser.close();
for (const p of [gateway, engine]) p.kill('SIGTERM');
await Promise.all([stopped(gateway), stopped(engine)]);
writeFileSync(path.join(outDir, 'engine.txt'), engine.out);
writeFileSync(path.join(outDir, 'gateway.txt'), gateway.out);
const m = /deadline\s+(\d+) misses on the virtual clock/.exec(engine.out);
if (!m) await fail(`no engine summary: ${engine.out.slice(-500)}`);
if (+m[1] !== 0 || misses !== 0) await fail(`deadline misses with clients connected: ${m[1]} (engine summary), ${misses} (state stream)`);
ok(`zero deadline misses on the virtual clock with clients connected (${/frames at/.test(engine.out) ? engine.out.match(/probe .*frames at \d+ Hz/)[0] : ''})`);
const canRx = /can rx\s+(.*)/.exec(engine.out); // the engine's CAN receive mailboxes (sc_hs_live.h)
if (canRx) ok(`engine's CAN receive: ${canRx[1]}`);
const gw = gateway.out.trim().split('\n').pop();
ok(gw);
console.log('PASS');
