// Drives the web page as a person would, in headless Chromium on SwiftShader's WebGPU: loads
// it, waits until its title says converged (or error), reads the frame back, takes a
// screenshot, drops a file that is not a groom on the picture (the page must say so and keep
// its scene), then orbits with the mouse, zooms with the wheel and turns the map with the
// panel's rotation slider, and reads the new converged frame and the settings it was rendered
// with, then switches to single scattering and does the same. (One convergence for the three
// moves: each is a minute of SwiftShader, and the replay of the reported settings checks them
// all.) Writes OUT/frame.f32, OUT/page.png, OUT/orbited.{f32,json}, OUT/single.{f32,json} and
// OUT/report.json (with the settings before the drag).
//
//   node page_check.mjs URL OUT [TIMEOUT_S]
import { launchChromium } from './browser.mjs';
import { writeFileSync } from 'node:fs';
import { join } from 'node:path';

const [url, out, timeoutText] = process.argv.slice(2);
const timeout = 1000 * Number(timeoutText ?? 600);
const browser = await launchChromium();
const report = { console: [], phasesMs: {} };
const t0 = Date.now();
const phase = (name) => { report.phasesMs[name] = Date.now() - t0; };
try {
  const page = await browser.newPage({ viewport: { width: 1400, height: 1000 } });
  page.on('console', (m) => report.console.push(`${m.type()}: ${m.text()}`));
  page.on('pageerror', (e) => report.console.push(`pageerror: ${e.message}`));
  phase('browser');
  await page.goto(url);
  const ending = (t) => t.endsWith('converged') || t.includes('error:');
  await page.waitForFunction(() => document.title.endsWith('converged') || document.title.includes('error:'),
    null, { timeout, polling: 250 });
  phase('first converged');
  report.title = await page.title();
  if (!ending(report.title) || report.title.includes('error:')) throw new Error(report.title);
  report.timing = await page.evaluate(() => window.strandlight.report);
  report.size = await page.evaluate(() => window.strandlight.size());
  report.describe = JSON.parse(await page.evaluate(() => window.strandlight.page.describe()));
  const frame = await page.evaluate(() => window.strandlight.frame());
  writeFileSync(join(out, 'frame.f32'), Buffer.from(frame, 'base64'));
  await page.locator('#view').screenshot({ path: join(out, 'page.png') });
  await page.screenshot({ path: join(out, 'whole-page.png') });

  phase('first frame read, screenshots');
  // A bad file dropped on the picture: a message, and the last good scene.
  await page.evaluate(() => {
    const file = new File([new Uint8Array([1, 2, 3, 4, 5])], 'broken.hair');
    const data = new DataTransfer();
    data.items.add(file);
    document.getElementById('view').dispatchEvent(new DragEvent('drop', { dataTransfer: data, bubbles: true, cancelable: true }));
  });
  await page.waitForFunction(() => window.strandlight.message() !== '', null, { timeout: 30000 });
  report.badFileMessage = await page.evaluate(() => window.strandlight.message());
  await page.waitForTimeout(500);
  report.titleAfterBadFile = await page.title();
  const after = await page.evaluate(() => window.strandlight.frame());
  report.frameKeptAfterBadFile = after === frame;

  phase('bad file');
  // Orbit (a drag of 8 moves of (+10, -3) px across the picture), zoom (two wheel steps
  // toward the hair) and turn the map as a person drags the slider to a value, then converge
  // again. The test checks the camera and the turn against this script.
  report.settingsBeforeDrag = JSON.parse(await page.evaluate(() => window.strandlight.page.settings_json()));
  report.drag = { moves: 8, dx: 10, dy: -3, wheelSteps: 2 };
  const box = await page.locator('#view').boundingBox();
  const [cx, cy] = [box.x + box.width / 2, box.y + box.height / 2];
  await page.mouse.move(cx, cy);
  await page.mouse.down();
  for (let i = 1; i <= 8; i++) await page.mouse.move(cx + 10 * i, cy - 3 * i);
  await page.mouse.up();
  // Back over the picture: the drag may end past its edge (a 160-pixel canvas), where the
  // wheel scrolls the page instead.
  await page.mouse.move(cx, cy);
  await page.mouse.wheel(0, -100);
  await page.mouse.wheel(0, -100);
  report.rotation = 211;
  await page.evaluate((degrees) => {
    const slider = document.getElementById('rotation');
    slider.value = String(degrees);
    slider.dispatchEvent(new Event('input', { bubbles: true }));
  }, report.rotation);
  await page.waitForFunction((old) => {
    const now = window.strandlight.frame();
    return now !== null && now !== old && window.strandlight.status() === 'converged';
  }, frame, { timeout, polling: 250 });
  phase('orbited converged');
  writeFileSync(join(out, 'orbited.f32'), Buffer.from(await page.evaluate(() => window.strandlight.frame()), 'base64'));
  writeFileSync(join(out, 'orbited.json'), await page.evaluate(() => window.strandlight.page.settings_json()));

  // Single scattering only, from the panel's choice.
  const orbited = await page.evaluate(() => window.strandlight.frame());
  await page.selectOption('#scattering', 'single');
  await page.waitForFunction((old) => {
    const now = window.strandlight.frame();
    return now !== null && now !== old && window.strandlight.status() === 'converged';
  }, orbited, { timeout, polling: 250 });
  phase('single converged');
  writeFileSync(join(out, 'single.f32'), Buffer.from(await page.evaluate(() => window.strandlight.frame()), 'base64'));
  writeFileSync(join(out, 'single.json'), await page.evaluate(() => window.strandlight.page.settings_json()));

} finally {
  writeFileSync(join(out, 'report.json'), JSON.stringify(report, null, 2));
  await browser.close();
}
