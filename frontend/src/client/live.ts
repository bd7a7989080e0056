/**
 * Live state of buses and axes, fed by the server's event WebSocket (`/api/ws/events`). Pages subscribe to the
 * event types they show; the hub keeps the last known state of each axis, the buses and the user as reactive
 * states (`lib/dom.ts`), so the project tree, the top bar and the pages bind to them instead of re-rendering.
 * While the socket is open the server watches the known drives' status words and sends `drive_state` on every
 * change, so axis states need no polling.
 */

import { setMotionClient, type AxisConfig, type UserInfo } from "./api";
import { busNames } from "./drives";
import type { EventMap, EventType, LiveEvent } from "./messages";
import { STATE_LABELS, decodeState, type DriveState } from "../lib/cia402";
import { state, type State } from "../lib/dom";

export type { LiveEvent } from "./messages";
export type { UserInfo } from "./api";

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

type Listener = (event: LiveEvent) => void;

const RECONNECT_MS = 2000;
const UNKNOWN: AxisStatus = { online: false, nmt: null, state: null, statusword: null, fault: false, faultText: "" };

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
  /** One state per axis (created on first read, so a binding may read an axis before anything is known of it). */
  private readonly axes = new Map<string, State<AxisStatus | undefined>>();
  /** The server's buses and their state, for the top bar. */
  readonly busStates: State<BusStatus[]> = state([]);
  readonly userState: State<UserInfo | null> = state(null);
  /** Whether the event socket is open: axis states and job ends then arrive as events, no polling needed. */
  readonly socketOpen: State<boolean> = state(false);
  private watched: AxisConfig[] = [];
  private socket: WebSocket | null = null;

  start(): void {
    this.connect();
  }

  connected(): boolean {
    return this.socketOpen.rawVal;
  }

  /** Send a message on the event socket (the hold-to-run keepalive); false when it is not open. */
  send(message: Record<string, unknown>): boolean {
    if (this.socket?.readyState !== WebSocket.OPEN) return false;
    this.socket.send(JSON.stringify(message));
    return true;
  }

  /** Subscribe to one event type ("*" for all); returns the unsubscribe function. */
  on<K extends EventType>(type: K, listener: (event: EventMap[K]) => void): () => void;
  on(type: string, listener: Listener): () => void;
  on(type: string, listener: Listener): () => void {
    let set = this.listeners.get(type);
    if (!set) this.listeners.set(type, (set = new Set()));
    set.add(listener);
    return () => set.delete(listener);
  }

  /** Called after every change of an axis, the buses or the user (for code that does not bind to the states). */
  onChange(listener: () => void): () => void {
    this.changeListeners.add(listener);
    return () => this.changeListeners.delete(listener);
  }

  /** The state of one axis; read inside a binding, the binding follows it. */
  axisState(bus: string, node: number): State<AxisStatus | undefined> {
    const key = axisKey(bus, node);
    let slot = this.axes.get(key);
    if (!slot) this.axes.set(key, (slot = state<AxisStatus | undefined>(undefined)));
    return slot;
  }

  axis(bus: string, node: number): AxisStatus | undefined {
    return this.axisState(bus, node).val;
  }

  buses(): BusStatus[] {
    return this.busStates.val;
  }

  user(): UserInfo | null {
    return this.userState.val;
  }

  setUser(user: UserInfo): void {
    this.userState.val = user;
    this.changed();
  }

  setBuses(buses: BusStatus[]): void {
    this.busStates.val = buses.map((bus) => ({ ...bus }));
    this.changed();
  }

  /** Which axes the tree shows; their status is fetched once and then kept up to date by events. */
  watchAxes(axes: AxisConfig[]): void {
    this.watched = axes;
    void this.refreshAxes();
  }

  /** Merge fresh knowledge about one axis (from a REST answer or an event). */
  updateAxis(bus: string, node: number, change: Partial<AxisStatus>): void {
    const slot = this.axisState(bus, node);
    const next = { ...(slot.rawVal ?? UNKNOWN), ...change };
    if (change.statusword !== undefined && change.statusword !== null) {
      next.state = decodeState(change.statusword);
      next.fault = next.state === "fault" || next.state === "fault_reaction_active";
      if (!next.fault) next.faultText = "";
    }
    slot.val = next;
    this.changed();
  }

  async refreshAxes(): Promise<void> {
    await Promise.all(this.watched.map((axis) => this.refreshAxis(axis)));
  }

  refreshAxis = async (_axis: AxisConfig): Promise<void> => {
    // Replaced by the app once the drive routes are known (keeps this module free of REST details).
  };

  private changed(): void {
    for (const listener of this.changeListeners) listener();
  }

  private connect(): void {
    const protocol = window.location.protocol === "https:" ? "wss:" : "ws:";
    const socket = (this.socket = new WebSocket(`${protocol}//${window.location.host}/api/ws/events`));
    socket.addEventListener("open", () => {
      this.socketOpen.val = true;
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
      this.socketOpen.val = false;
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
