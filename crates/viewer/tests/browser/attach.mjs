// Attaches watchers to a running `animats view` for the PERFORMANCE.md
// figures: N WebSocket clients, or a headless Chromium tab drawing the page.
//   node --experimental-websocket attach.mjs URL SECONDS (ws N | browser)
import { chromium } from 'playwright-core';

const [url, seconds, kind, count] = process.argv.slice(2);
const ms = 1000 * Number(seconds);
if (kind === 'browser') {
  const browser = await chromium.launch({
    executablePath: process.env.CHROMIUM ?? '/usr/bin/chromium',
    args: ['--no-sandbox', '--disable-gpu', '--use-angle=swiftshader', '--enable-unsafe-swiftshader'],
  });
  const page = await browser.newPage({ viewport: { width: 1100, height: 700 } });
  await page.goto(url);
  await new Promise((r) => setTimeout(r, ms));
  console.log(`browser tab: ${await page.evaluate(() => window.__viewer.frames)} frames`);
  await browser.close();
} else {
  const n = Number(count ?? 1);
  const frames = new Array(n).fill(0);
  const sockets = frames.map((_, k) => {
    const ws = new WebSocket(url.replace(/^http/, 'ws') + 'ws');
    ws.onmessage = () => { frames[k] += 1; };
    return ws;
  });
  await new Promise((r) => setTimeout(r, ms));
  sockets.forEach((ws) => ws.close());
  console.log(`${n} WebSocket clients: ${frames.join(' ')} frames`);
}
