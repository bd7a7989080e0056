import { afterEach, describe, expect, it, vi } from "vitest";
import { runJob, type JobInfo } from "../client/jobs";
import { LiveHub } from "../client/live";

const running = (id: string): JobInfo => ({ id, operation: "restore", state: "running", result: null, error: null, started: 0 });

/** Let the start request's promise chain run. */
const settled = () => new Promise((resolve) => setTimeout(resolve, 0));

afterEach(() => vi.unstubAllGlobals());

describe("server jobs", () => {
  it("follows the job's own progress and answers its end", async () => {
    const hub = new LiveHub();
    const seen: number[] = [];
    const answer = runJob(hub, async () => running("job3"), (event) => seen.push(Number(event.done)));
    await settled();
    hub.emit({ type: "progress", job: "job2", done: 99 });
    hub.emit({ type: "progress", job: "job3", done: 4 });
    hub.emit({ type: "job", id: "job2", state: "done" });
    hub.emit({ type: "job", id: "job3", state: "done", result: { 1: [] }, error: null });
    const job = await answer;
    expect(job.state).toBe("done");
    expect(seen).toEqual([4]);
  });

  it("a job that ended before its id came back is answered at once", async () => {
    const hub = new LiveHub();
    const job = await runJob(hub, async () => {
      hub.emit({ type: "job", id: "job5", state: "failed", error: "node 1: no answer" });
      return running("job5");
    }, () => undefined);
    expect(job).toMatchObject({ state: "failed", error: "node 1: no answer" });
  });

  it("aborting the signal cancels the job on the server and answers the cancelled job", async () => {
    const calls: string[] = [];
    vi.stubGlobal("fetch", vi.fn(async (url: string, init: RequestInit) => {
      calls.push(`${init.method} ${url}`);
      return new Response(JSON.stringify(running("job7")), { status: 200, headers: { "Content-Type": "application/json" } });
    }));
    const hub = new LiveHub();
    const controller = new AbortController();
    const answer = runJob(hub, async () => running("job7"), () => undefined, controller.signal);
    await settled();
    controller.abort();
    expect(calls).toEqual(["POST /api/jobs/job7/cancel"]);
    hub.emit({ type: "job", id: "job7", state: "cancelled", result: { 1: [{ cancelled: true }] }, error: null });
    expect((await answer).state).toBe("cancelled");
  });
});
