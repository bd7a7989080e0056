/**
 * Server jobs (backup, restore, commission): start one, follow its `progress` events and wait for its end on the
 * event socket, cancel it (`POST /api/jobs/{id}/cancel`: the server stops at the next object or file boundary
 * and the job ends `cancelled` with what was done so far).
 */

import { get, post } from "./api";
import type { LiveEvent, LiveHub } from "./live";
import type { Narrow, Schemas } from "./schema-types";

export type JobState = "running" | "done" | "partial" | "failed" | "cancelled";

/** A server job (`JobModel`); its `result` depends on the operation, which the schema leaves open. */
export type JobInfo<R = unknown> = Narrow<Schemas["JobModel"], { state: JobState; result?: R | null }>;

/** While the event socket is down the job's end is polled at this period instead. */
const POLL_MS = 2000;

export const cancelJob = (id: string) => post<JobInfo>(`/api/jobs/${encodeURIComponent(id)}/cancel`);
export const getJob = <R>(id: string) => get<JobInfo<R>>(`/api/jobs/${encodeURIComponent(id)}`);

/**
 * Start a job with `start` and answer it once it ended. `onProgress` gets the job's progress events; aborting
 * `signal` cancels the job on the server (the answer then is the cancelled job with its partial result).
 */
export async function runJob<R>(live: LiveHub, start: () => Promise<JobInfo<R>>, onProgress: (event: LiveEvent) => void,
  signal?: AbortSignal): Promise<JobInfo<R>> {
  let id: string | null = null;
  // A short job can end before its id comes back from the start request: remember every ending meanwhile.
  const ended = new Map<string, JobInfo<R>>();
  let finish: (job: JobInfo<R>) => void = () => undefined;
  const done = new Promise<JobInfo<R>>((resolve) => (finish = resolve));
  const offJob = live.on("job", (event) => {
    const job = event as unknown as JobInfo<R>;
    if (job.id === id) finish(job);
    else ended.set(job.id, job);
  });
  const offProgress = live.on("progress", (event) => {
    if (id !== null && event.job === id) onProgress(event);
  });
  let poll: ReturnType<typeof setInterval> | undefined;
  const cancel = () => {
    if (id !== null) void cancelJob(id).catch(() => undefined);
  };
  try {
    const started = await start();
    id = started.id;
    if (started.state !== "running") return started;
    const early = ended.get(started.id);
    if (early) return early;
    signal?.addEventListener("abort", cancel);
    if (signal?.aborted) cancel();
    poll = setInterval(() => {
      if (live.connected()) return;
      void getJob<R>(started.id).then((job) => job.state !== "running" && finish(job), () => undefined);
    }, POLL_MS);
    return await done;
  } finally {
    offJob();
    offProgress();
    if (poll !== undefined) clearInterval(poll);
    signal?.removeEventListener("abort", cancel);
  }
}
