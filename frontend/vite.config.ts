import { defineConfig } from "vitest/config";

// The backend serves the built UI from its package (backend/servostudio/static);
// in development `npm run dev` proxies the API to a running `servostudio serve`.
export default defineConfig({
  build: {
    outDir: "../backend/servostudio/static",
    emptyOutDir: true,
  },
  server: {
    proxy: {
      "/api": { target: "http://127.0.0.1:8000", ws: true },
      "/openapi.json": "http://127.0.0.1:8000",
      "/docs": "http://127.0.0.1:8000",
    },
  },
  test: {
    environment: "jsdom",
  },
});
