import './style.css';
import { App } from './app';

function fatal(message: string): void {
  const box = document.getElementById('error');
  const text = document.getElementById('error-text');
  if (box && text) {
    text.textContent = message;
    box.hidden = false;
  }
}

const canvas = document.getElementById('view');
if (!(canvas instanceof HTMLCanvasElement)) {
  fatal('index.html lacks the #view canvas');
} else {
  try {
    new App(canvas);
  } catch (e) {
    fatal(`The viewer could not start: ${e instanceof Error ? e.message : String(e)} (is WebGL 2 available?)`);
  }
}
