import { afterEach, describe, expect, it, vi } from "vitest";
import { App } from "../app";
import { commissionPanel } from "../components/commissionjob";
import { formDialog, messageView, type Message } from "../components/ui";
import { h, state } from "../lib/dom";

const settled = () => new Promise((resolve) => setTimeout(resolve, 0));
const testid = (root: ParentNode, id: string) => root.querySelector<HTMLElement>(`[data-testid="${id}"]`);

afterEach(() => {
  vi.unstubAllGlobals();
  document.body.textContent = "";
});

describe("commission panel", () => {
  it("shows a progress bar per axis from the job's events, then the report", async () => {
    const requests: string[] = [];
    vi.stubGlobal("fetch", vi.fn(async (url: string, init: RequestInit) => {
      requests.push(`${init.method} ${url} ${String(init.body)}`);
      return Response.json({ id: "job4", operation: "commission", state: "running", result: null, error: null, started: 0 });
    }));
    const app = new App(document.createElement("div"));
    let done = 0;
    const panel = commissionPanel(app, "demo", () => done++);
    document.body.append(panel);
    const check = testid(panel, "commission-check") as HTMLButtonElement;
    const cancel = testid(panel, "commission-cancel") as HTMLButtonElement;
    expect(cancel.disabled).toBe(true);
    check.click();
    await settled();
    expect(requests).toEqual(['POST /api/projects/demo/commission {"direction":"check"}']);
    expect(check.disabled).toBe(true);
    expect(cancel.disabled).toBe(false);
    app.live.emit({ type: "progress", job: "job4", operation: "commission", step: "identify", axes: [{ axis: "X" }, { axis: "Y" }] });
    app.live.emit({ type: "progress", job: "job4", operation: "upload", axis: "X", file: "DRIVEPAR.TXT", done: 3, total: 10 });
    app.live.emit({ type: "progress", job: "other", operation: "upload", axis: "Y", done: 9, total: 10 });
    const lines = [...panel.querySelectorAll(".progress-line")];
    expect(lines.map((line) => line.textContent)).toEqual(["Xupload DRIVEPAR.TXT 3/10", "Yidentify…"]);
    expect((lines[0].querySelector("progress") as HTMLProgressElement).value).toBe(3);
    app.live.emit({
      type: "job", id: "job4", operation: "commission", state: "done", error: null, started: 0,
      result: { ok: false, direction: "check", axes: [
        { axis: "X", node_id: 1, bus_id: "sim", status: "ok", problem: null, ok: true, error: null, files: [] },
        { axis: "Y", node_id: 2, bus_id: null, status: "offline", problem: "no answer", ok: false, error: null, files: [] },
      ] },
    });
    await settled();
    expect(testid(panel, "commission-result")!.textContent).toBe("check: some axes need attention");
    expect([...panel.querySelectorAll("tbody tr")].map((row) => row.className)).toEqual(["", "differs"]);
    expect(panel.querySelector("tbody")!.textContent).toContain("no answer");
    expect(check.disabled).toBe(false);
    expect(cancel.disabled).toBe(true);
    expect(done).toBe(1);
  });

  it("shows the server's refusal to start", async () => {
    vi.stubGlobal("fetch", vi.fn(async () => Response.json({ detail: "project demo has no axis" }, { status: 422 })));
    const app = new App(document.createElement("div"));
    const panel = commissionPanel(app, "demo", () => undefined);
    (testid(panel, "commission-check") as HTMLButtonElement).click();
    await settled();
    await settled();
    expect(testid(panel, "commission-result")!.textContent).toBe("project demo has no axis");
    expect((testid(panel, "commission-check") as HTMLButtonElement).disabled).toBe(false);
  });
});

describe("form dialog", () => {
  it("shows the refusal in the dialog and closes once the action succeeds", async () => {
    let attempts = 0;
    const name = h("input", { type: "text" });
    formDialog({
      title: "New project", body: [name], confirm: "Create", confirmTestid: "create", errorTestid: "dialog-error",
      submit: async () => {
        attempts++;
        if (attempts === 1) throw new Error("a project named demo exists");
      },
    });
    expect(document.querySelector(".dialog")).not.toBeNull();
    testid(document, "create")!.click();
    await settled();
    expect(testid(document, "dialog-error")!.textContent).toBe("a project named demo exists");
    testid(document, "create")!.click();
    await settled();
    expect(document.querySelector(".dialog")).toBeNull();
    expect(attempts).toBe(2);
  });

  it("Cancel closes without running the action", () => {
    let ran = false;
    formDialog({ title: "T", body: [], confirm: "OK", submit: async () => void (ran = true) });
    [...document.querySelectorAll<HTMLButtonElement>(".dialog button")].find((b) => b.textContent === "Cancel")!.click();
    expect(document.querySelector(".dialog")).toBeNull();
    expect(ran).toBe(false);
  });
});

describe("message line", () => {
  it("shows the current message with its tone and test id, nothing while null", () => {
    const message = state<Message | null>(null);
    const line = messageView(message);
    expect(line.textContent).toBe("");
    message.val = { text: "refused", tone: "error", testid: "bus-error" };
    expect(testid(line, "bus-error")!.className).toBe("message error");
    message.val = null;
    expect(line.childElementCount).toBe(0);
  });
});
