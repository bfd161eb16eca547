import { defineConfig } from 'vite';

// The viewer is embedded in the `pmc` binary and served at `/`; relative asset URLs keep it
// working behind any prefix. `npm run dev` proxies the API to a local `pmc serve`.
export default defineConfig({
  base: './',
  build: {
    outDir: 'dist',
    assetsDir: 'assets',
    emptyOutDir: true,
    target: 'es2022',
    chunkSizeWarningLimit: 1024,
  },
  server: {
    proxy: {
      '/api': 'http://127.0.0.1:8080',
    },
  },
});
