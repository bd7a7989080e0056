/**
 * The quick test's motion state of one axis and its actions: the running (else last) motion, the axis's limits,
 * the device's homing methods, and hold-to-run — a held button starts its motion with `press` and ends it with
 * `release`; the keepalives run in between (`client/motion.ts`, `HoldToRun`).
 */

import { errorText } from "../ui";
import { serverBus } from "../../client/drives";
import { HoldToRun, motionApi, type HomingMethod, type KeepaliveSink, type Motion, type MotionLimits, type PageView } from "../../client/motion";
import type { LiveHub } from "../../client/live";
import { state, type Scope } from "../../lib/dom";

export interface QuickMotionContext {
  bus: string;
  node: number;
  device: string;
  live: Pick<LiveHub, "on"> & KeepaliveSink;
  scope: Scope;
  view?: PageView;
}

const ENDED = new Set(["done", "stopped", "failed"]);

export class QuickMotion {
  readonly motion = state<Motion | null>(null);
  readonly limits = state<MotionLimits | null>(null);
  readonly methods = state<HomingMethod[]>([]);
  readonly error = state<string | null>(null);
  private readonly hold: HoldToRun;
  private pressed = false;

  constructor(private readonly context: QuickMotionContext) {
    const { bus, node, live, scope, view } = context;
    this.hold = new HoldToRun(live, () => serverBus(bus), node, () => this.release("the tab was hidden or lost focus"), view);
    scope.add(live.on("motion", (event) => {
      if (event.bus === serverBus(bus) && event.node === node) this.show(event);
    }));
    scope.add(() => this.hold.end());
  }

  async load(): Promise<void> {
    const { bus, node, device } = this.context;
    await Promise.all([
      motionApi.current(bus, node).then((motion) => this.show(motion)),
      motionApi.limits(bus, node).then((limits) => (this.limits.val = limits)),
      motionApi.homingMethods(device).then((methods) => (this.methods.val = methods)).catch(() => undefined),
    ]).catch((error: unknown) => (this.error.val = errorText(error)));
  }

  /** A held button went down: keepalives from now on, and the motion with `hold` started. */
  async press(label: string, start: () => Promise<Motion>): Promise<void> {
    this.error.val = null;
    if (!this.hold.start()) {
      this.error.val = `${label}: hold-to-run needs this tab visible and focused`;
      return;
    }
    this.pressed = true;
    try {
      this.show(await start());
    } catch (error) {
      this.hold.end();
      this.pressed = false;
      this.error.val = `${label}: ${errorText(error)}`;
      return;
    }
    if (!this.pressed) await this.stop(); // released before the server answered
  }

  /** The button went up (or the tab lost focus): no more keepalives, and a quick stop of what still runs. */
  release(why = ""): void {
    if (!this.pressed && !this.hold.holding) return;
    this.pressed = false;
    this.hold.end();
    if (why) this.error.val = `Stopped: ${why}`;
    const motion = this.motion.rawVal;
    if (!motion || !ENDED.has(motion.state)) void this.stop();
  }

  async stop(): Promise<void> {
    try {
      this.show(await motionApi.stop(this.context.bus, this.context.node));
    } catch (error) {
      this.error.val = `Stop: ${errorText(error)}`;
    }
  }

  private show(motion: Motion | null): void {
    this.motion.val = laterMotion(this.motion.rawVal, motion);
  }

  async setLimits(limits: Partial<MotionLimits>): Promise<boolean> {
    try {
      this.limits.val = await motionApi.setLimits(this.context.bus, this.context.node, limits);
      return true;
    } catch (error) {
      this.error.val = `Limits: ${errorText(error)}`;
      return false;
    }
  }

  jog(velocity: number): Promise<void> {
    return this.press("Jog", () => motionApi.jog(this.context.bus, this.context.node, velocity));
  }

  move(distance: number, absolute: boolean, velocity: number | null): Promise<void> {
    return this.press("Move", () => motionApi.move(this.context.bus, this.context.node, distance, absolute, velocity));
  }

  home(method: number, velocity: number | null): Promise<void> {
    return this.press("Homing", () => motionApi.home(this.context.bus, this.context.node, method, velocity));
  }
}

/**
 * What the status line keeps when news of a motion arrives. An HTTP answer can come after the event of a later
 * change (a homing over before the request that started it was answered, on a loaded host): a motion never goes
 * back from ended to running, nor loses the position its end was read with. A stop that found nothing running
 * (no motion in its answer: the motion had just ended) does not hide how that motion ended.
 */
export function laterMotion(shown: Motion | null, news: Motion | null): Motion | null {
  if (shown?.motion && news && !news.motion && ENDED.has(shown.state)) return shown;
  if (!shown?.motion || !news?.motion || shown.motion !== news.motion) return news;
  return progress(news) >= progress(shown) ? news : shown;
}

function progress(motion: Motion): number {
  if (!ENDED.has(motion.state)) return 0;
  return motion.position === null || motion.position === undefined ? 1 : 2;
}

/** The motion as the status line says it. */
export function motionText(motion: Motion | null): string {
  if (!motion?.motion) return motion?.reason ? `Stopped: ${motion.reason}` : "No motion yet";
  const what = { jog: "Jog", move: "Move", home: "Homing" }[motion.kind ?? "jog"];
  const where = motion.position !== null && motion.position !== undefined ? ` · position ${motion.position}` : "";
  const reason = motion.reason ? ` — ${motion.reason}` : "";
  return `${what} ${motion.state}${where}${reason}`;
}

/**
 * The homing method the page shows and starts: the one picked when the device has it, else the device's first
 * (CiA 402's 35 is no TTA-PRO configuration); the picked one while the methods are not known yet.
 */
export function homingChoice(methods: Pick<HomingMethod, "method">[], picked: string): string {
  if (methods.length === 0 || methods.some((item) => String(item.method) === picked)) return picked;
  return String(methods[0].method);
}
