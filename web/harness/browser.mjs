// Headless Chromium with WebGPU on SwiftShader, as the page's test and scripts/first-minute.sh
// open it (CHROMIUM names another binary; CHROMIUM_LOG=1 sends its log to stderr).
import { chromium } from 'playwright-core';

export function launchChromium() {
  return chromium.launch({
    executablePath: process.env.CHROMIUM ?? '/usr/bin/chromium',
    args: [
      '--headless=new', '--no-sandbox', '--enable-unsafe-webgpu', '--use-webgpu-adapter=swiftshader',
      '--enable-unsafe-swiftshader', '--disable-background-networking', '--disable-component-update',
      '--no-first-run', '--disable-sync', '--disable-quic',
      ...(process.env.CHROMIUM_LOG ? ['--enable-logging=stderr', '--v=0'] : []),
    ],
  });
}
