/** Application shell: top bar with the server connection state; pages mount into <main>. */

import type { Health } from "./api";

export type ServerState = { kind: "connecting" } | { kind: "online"; health: Health } | { kind: "offline"; reason: string };

export function renderShell(root: HTMLElement): { main: HTMLElement; status: HTMLElement } {
  root.innerHTML = `
    <header class="topbar">
      <span class="brand">Servo Studio</span>
      <nav class="links"><a href="/docs" target="_blank" rel="noopener">REST API</a></nav>
      <span class="server-status" data-testid="server-status"></span>
    </header>
    <main class="content"></main>`;
  return {
    main: root.querySelector<HTMLElement>("main")!,
    status: root.querySelector<HTMLElement>(".server-status")!,
  };
}

export function showServerState(element: HTMLElement, state: ServerState): void {
  element.dataset.state = state.kind;
  switch (state.kind) {
    case "connecting":
      element.textContent = "Connecting to server…";
      break;
    case "online":
      element.textContent = `Server online · v${state.health.version}`;
      break;
    case "offline":
      element.textContent = `Server offline: ${state.reason}`;
      break;
  }
}
