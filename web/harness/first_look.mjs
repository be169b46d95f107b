// Opens the page in headless Chromium (WebGPU on SwiftShader) as a new user would, waits until
// its title says converged (or error) and writes the page's own timing (first preview,
// converged, ticks) to OUT/report.json. For scripts/first-minute.sh; page_check.mjs is the test.
//
//   node first_look.mjs URL OUT [TIMEOUT_S]
import { launchChromium } from './browser.mjs';
import { writeFileSync } from 'node:fs';
import { join } from 'node:path';

const [url, out, timeoutText] = process.argv.slice(2);
const timeout = 1000 * Number(timeoutText ?? 600);
const browser = await launchChromium();
try {
  const page = await browser.newPage({ viewport: { width: 1400, height: 1000 } });
  await page.goto(url);
  await page.waitForFunction(() => document.title.endsWith('converged') || document.title.includes('error:'),
    null, { timeout, polling: 250 });
  const title = await page.title();
  if (title.includes('error:')) throw new Error(title);
  const timing = await page.evaluate(() => window.strandlight.report);
  await page.screenshot({ path: join(out, 'whole-page.png') });
  writeFileSync(join(out, 'report.json'), JSON.stringify({ title, timing }, null, 1));
} finally {
  await browser.close();
}
