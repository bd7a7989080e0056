import "./style.css";
import { getHealth } from "./api";
import { renderShell, showServerState } from "./shell";

const HEALTH_INTERVAL_MS = 5000;

const { status } = renderShell(document.querySelector<HTMLElement>("#app")!);
showServerState(status, { kind: "connecting" });

async function refreshHealth(): Promise<void> {
  try {
    showServerState(status, { kind: "online", health: await getHealth() });
  } catch (error) {
    showServerState(status, { kind: "offline", reason: (error as Error).message });
  }
}

void refreshHealth();
setInterval(refreshHealth, HEALTH_INTERVAL_MS);
