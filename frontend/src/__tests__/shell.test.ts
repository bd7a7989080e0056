import { describe, expect, it } from "vitest";
import { getHealth } from "../api";
import { renderShell, showServerState } from "../shell";

describe("shell", () => {
  it("shows the server version once online and the reason when offline", () => {
    const root = document.createElement("div");
    const { status } = renderShell(root);
    showServerState(status, { kind: "online", health: { status: "ok", version: "9.8.7" } });
    expect(status.textContent).toBe("Server online · v9.8.7");
    expect(status.dataset.state).toBe("online");
    showServerState(status, { kind: "offline", reason: "/api/health: HTTP 503" });
    expect(status.textContent).toContain("HTTP 503");
    expect(status.dataset.state).toBe("offline");
  });
});

describe("api", () => {
  it("rejects a non-2xx answer with the path and status", async () => {
    const failing = (async () => new Response("", { status: 500 })) as unknown as typeof fetch;
    await expect(getHealth(failing)).rejects.toThrow("/api/health: HTTP 500");
  });

  it("parses the health document", async () => {
    const ok = (async () => Response.json({ status: "ok", version: "1.2.3" })) as unknown as typeof fetch;
    await expect(getHealth(ok)).resolves.toEqual({ status: "ok", version: "1.2.3" });
  });
});
