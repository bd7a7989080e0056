/**
 * Live state of buses and axes, fed by the server's event WebSocket (`/api/ws/events`). Pages subscribe to the
 * event types they show; the hub keeps the last known state of each axis for the project tree and the top bar.
 * While the socket is open the server watches the known drives' status words and sends `drive_state` on every
 * change, so axis states need no polling.
 */

import { setMotionClient, type AxisConfig } from "./api";
import { busNames } from "./drives";
import { STATE_LABELS, decodeState, type DriveState } from "../lib/cia402";

export interface AxisStatus {
  online: boolean;
  nmt: string | null;
  state: DriveState | null;
  statusword: number | null;
  fault: boolean;
  faultText: string;
}

export interface BusStatus {
  name: string;
  state: string;
}

export interface UserInfo {
  name: string;
  level: string;
}

export type LiveEvent = Record<string, unknown> & { type: string };
type Listener = (event: LiveEvent) => void;

const RECONNECT_MS = 2000;

export function axisKey(bus: string, node: number): string {
  return `${bus}:${node}`;
}

/** Short text and colour of an axis's state for the tree: fault wins, then CiA 402 state, then NMT, then offline. */
export function axisStateText(status: AxisStatus | undefined): { text: string; tone: string } {
  if (!status) return { text: "…", tone: "idle" };
  if (!status.online) return { text: "offline", tone: "idle" };
  if (status.fault) return { text: status.faultText ? `Fault: ${status.faultText}` : "Fault", tone: "bad" };
  if (status.state) {
    return { text: STATE_LABELS[status.state], tone: status.state === "operation_enabled" ? "ok" : "warn" };
  }
  return { text: status.nmt ? status.nmt.toLowerCase() : "online", tone: "warn" };
}

export class LiveHub {
  private readonly listeners = new Map<string, Set<Listener>>();
  private readonly changeListeners = new Set<() => void>();
  private readonly axes = new Map<string, AxisStatus>();
  private readonly busStates = new Map<string, string>();
  private currentUser: UserInfo | null = null;
  private watched: AxisConfig[] = [];
  private socketOpen = false;

  start(): void {
    this.connect();
  }

  /** Whether the event socket is open: axis states and job ends then arrive as events, no polling needed. */
  connected(): boolean {
    return this.socketOpen;
  }

  /** Subscribe to one event type ("*" for all); returns the unsubscribe function. */
  on(type: string, listener: Listener): () => void {
    let set = this.listeners.get(type);
    if (!set) this.listeners.set(type, (set = new Set()));
    set.add(listener);
    return () => set!.delete(listener);
  }

  onChange(listener: () => void): () => void {
    this.changeListeners.add(listener);
    return () => this.changeListeners.delete(listener);
  }

  axis(bus: string, node: number): AxisStatus | undefined {
    return this.axes.get(axisKey(bus, node));
  }

  buses(): BusStatus[] {
    return [...this.busStates].map(([name, state]) => ({ name, state }));
  }

  user(): UserInfo | null {
    return this.currentUser;
  }

  setUser(user: UserInfo): void {
    this.currentUser = user;
    this.changed();
  }

  setBuses(buses: BusStatus[]): void {
    this.busStates.clear();
    for (const bus of buses) this.busStates.set(bus.name, bus.state);
    this.changed();
  }

  /** Which axes the tree shows; their status is fetched once and then kept up to date by events. */
  watchAxes(axes: AxisConfig[]): void {
    this.watched = axes;
    void this.refreshAxes();
  }

  /** Merge fresh knowledge about one axis (from a REST answer or an event). */
  updateAxis(bus: string, node: number, change: Partial<AxisStatus>): void {
    const key = axisKey(bus, node);
    const previous = this.axes.get(key) ?? { online: false, nmt: null, state: null, statusword: null, fault: false, faultText: "" };
    const next = { ...previous, ...change };
    if (change.statusword !== undefined && change.statusword !== null) {
      next.state = decodeState(change.statusword);
      next.fault = next.state === "fault" || next.state === "fault_reaction_active";
      if (!next.fault) next.faultText = "";
    }
    this.axes.set(key, next);
    this.changed();
  }

  async refreshAxes(): Promise<void> {
    await Promise.all(this.watched.map((axis) => this.refreshAxis(axis)));
  }

  refreshAxis = async (_axis: AxisConfig): Promise<void> => {
    // Replaced in drives.ts once the drive routes are known (keeps this module free of REST details).
  };

  private changed(): void {
    for (const listener of this.changeListeners) listener();
  }

  private connect(): void {
    const protocol = window.location.protocol === "https:" ? "wss:" : "ws:";
    const socket = new WebSocket(`${protocol}//${window.location.host}/api/ws/events`);
    socket.addEventListener("open", () => {
      this.socketOpen = true;
      void this.refreshAxes();
      this.emit({ type: "ws_open" });
    });
    socket.addEventListener("message", (message) => {
      try {
        const event = JSON.parse(String(message.data)) as LiveEvent;
        if (event.type === "hello") setMotionClient(String(event.client));
        this.emit(event);
      } catch {
        // A frame that is not JSON is not an event.
      }
    });
    socket.addEventListener("close", () => {
      this.socketOpen = false;
      setMotionClient(null);
      setTimeout(() => this.connect(), RECONNECT_MS);
    });
  }

  emit(event: LiveEvent): void {
    this.applyToState(event);
    for (const type of [event.type, "*"]) {
      for (const listener of this.listeners.get(type) ?? []) listener(event);
    }
  }

  private applyToState(event: LiveEvent): void {
    if (typeof event.bus !== "string") return;
    for (const bus of busNames(event.bus)) this.applyToAxis(bus, event);
  }

  private applyToAxis(bus: string, event: LiveEvent): void {
    const node = typeof event.node === "number" ? event.node : null;
    if (node === null) return;
    switch (event.type) {
      case "nmt_state":
      case "heartbeat_back":
        this.updateAxis(bus, node, { online: true, nmt: String(event.nmt_state) });
        break;
      case "bootup":
        this.updateAxis(bus, node, { online: true, nmt: "PRE-OPERATIONAL" });
        break;
      case "heartbeat_lost":
        this.updateAxis(bus, node, { online: false });
        break;
      case "emcy": {
        const faults = (event.faults as { name: string }[] | undefined) ?? [];
        if (event.cleared) this.updateAxis(bus, node, { fault: false, faultText: "" });
        else this.updateAxis(bus, node, { online: true, fault: true, faultText: faults[0]?.name ?? String(event.cia402_text ?? "") });
        break;
      }
      case "state":
      case "drive_state":
        if (typeof event.statusword === "number") this.updateAxis(bus, node, { online: true, statusword: event.statusword });
        break;
    }
  }
}
