/**
 * The quick test's motions (`/api/buses/{bus}/nodes/{node}/motion…`, docs/motion-safety.md): jog, move, home, stop,
 * the limits, the homing methods of a device — and hold-to-run. Every motion this page starts is held: the page
 * sends the keepalive on its event socket every `KEEPALIVE_MS` while the button is held and the tab is visible and
 * focused; when it stops (button released, tab hidden or blurred, page closed or frozen) the server quick-stops
 * the axis within 200 ms of the last keepalive.
 */

import { get, post, put } from "./api";
import { serverBus, whenMapped } from "./drives";
import type { Schemas } from "./schema-types";

export type Motion = Schemas["MotionModel"];
export type MotionLimits = Schemas["LimitsModel"];
export type HomingMethod = Schemas["HomingMethodModel"];

/** The server's hold timeout is 100 ms (services/motion/hold.py): two keepalive periods. */
export const KEEPALIVE_MS = 50;

const e = encodeURIComponent;
const motionPath = (bus: string, node: number) => `/api/buses/${e(serverBus(bus))}/nodes/${node}/motion`;

export const motionApi = {
  current: (bus: string, node: number) => whenMapped(() => get<Motion | null>(motionPath(bus, node))),
  jog: (bus: string, node: number, velocity: number) =>
    whenMapped(() => post<Motion>(`${motionPath(bus, node)}/jog`, { velocity, seconds: null, hold: true })),
  move: (bus: string, node: number, distance: number, absolute: boolean, velocity: number | null) =>
    whenMapped(() => post<Motion>(`${motionPath(bus, node)}/move`, { distance, absolute, velocity, hold: true })),
  home: (bus: string, node: number, method: number, velocity: number | null) =>
    whenMapped(() => post<Motion>(`${motionPath(bus, node)}/home`, { method, velocity, hold: true })),
  stop: (bus: string, node: number) => whenMapped(() => post<Motion>(`${motionPath(bus, node)}/stop`)),
  limits: (bus: string, node: number) => whenMapped(() => get<MotionLimits>(`${motionPath(bus, node)}/limits`)),
  setLimits: (bus: string, node: number, limits: Partial<MotionLimits>) =>
    whenMapped(() => put<MotionLimits>(`${motionPath(bus, node)}/limits`, limits)),
  homingMethods: (device: string) => get<HomingMethod[]>(`/api/homing-methods/${e(device)}`),
};

/** Where keepalives go: the page's event socket (`LiveHub.send`). */
export interface KeepaliveSink {
  send(message: Record<string, unknown>): boolean;
}

/** What the page looks like to the hold: visible and focused, or not (injectable for tests). */
export interface PageView {
  visible(): boolean;
  focused(): boolean;
  on(event: "blur" | "visibilitychange" | "pagehide", listener: () => void): () => void;
}

export const browserPage: PageView = {
  visible: () => document.visibilityState === "visible",
  focused: () => document.hasFocus(),
  on: (event, listener) => {
    const target: EventTarget = event === "visibilitychange" ? document : window;
    target.addEventListener(event, listener);
    return () => target.removeEventListener(event, listener);
  },
};

/**
 * One held button's keepalives: `start` sends one at once and then every `KEEPALIVE_MS`; they end with `end`, or by
 * themselves when the tab is hidden or loses focus (then `onLost` runs: the page stops the motion at once).
 */
export class HoldToRun {
  private timer: ReturnType<typeof setInterval> | null = null;
  private unlisten: (() => void)[] = [];

  constructor(
    private readonly sink: KeepaliveSink,
    private readonly bus: () => string,
    private readonly node: number,
    private readonly onLost: () => void,
    private readonly view: PageView = browserPage,
  ) {}

  get holding(): boolean {
    return this.timer !== null;
  }

  /** Start holding; false (nothing sent) when the page may not hold: hidden or not focused. */
  start(): boolean {
    this.end();
    if (!this.mayHold()) return false;
    const lost = () => this.lose();
    this.unlisten = [this.view.on("blur", lost), this.view.on("visibilitychange", lost), this.view.on("pagehide", lost)];
    this.timer = setInterval(() => this.tick(), KEEPALIVE_MS);
    this.send();
    return true;
  }

  end(): void {
    if (this.timer !== null) clearInterval(this.timer);
    this.timer = null;
    for (const stop of this.unlisten) stop();
    this.unlisten = [];
  }

  private mayHold(): boolean {
    return this.view.visible() && this.view.focused();
  }

  private tick(): void {
    if (this.mayHold()) this.send();
    else this.lose();
  }

  private lose(): void {
    if (!this.holding || this.mayHold()) return;
    this.end();
    this.onLost();
  }

  private send(): void {
    this.sink.send({ type: "keepalive", bus: this.bus(), node: this.node });
  }
}
