/**
 * Client of the server's `/api/ws/terminal` socket: continuous monitoring of up to 32 objects on
 * up to 4 axes (the server samples them, the page only renders), and writes. The dashboard and the dialog
 * terminal page both use it, so live values never need REST polling.
 */

import { getMotionClient } from "./api";
import type { ObjectValue } from "./drives";
import type { TerminalMessage, WatchItem, WatchRow } from "./messages";

export type { WatchItem, WatchRow } from "./messages";

type Pending = { resolve: (value: unknown) => void; reject: (error: Error) => void };

const RECONNECT_MS = 1500;

export class TerminalSocket {
  private socket: WebSocket | null = null;
  private queue: Pending[] = [];
  private watchMessage: unknown = null;
  private closed = false;
  private ready: Promise<void>;
  onRows: ((rows: WatchRow[]) => void) | null = null;
  onError: ((message: string) => void) | null = null;
  onConnection: ((open: boolean) => void) | null = null;

  constructor() {
    this.ready = this.connect();
  }

  private connect(): Promise<void> {
    return new Promise((resolve) => {
      const protocol = window.location.protocol === "https:" ? "wss:" : "ws:";
      const socket = new WebSocket(`${protocol}//${window.location.host}/api/ws/terminal`);
      this.socket = socket;
      socket.addEventListener("open", () => {
        this.onConnection?.(true);
        if (this.watchMessage) socket.send(JSON.stringify(this.watchMessage));
        resolve();
      });
      socket.addEventListener("message", (message) => this.onMessage(String(message.data)));
      socket.addEventListener("close", () => {
        this.onConnection?.(false);
        for (const pending of this.queue) pending.reject(new Error("connection to the server lost"));
        this.queue = [];
        if (!this.closed) setTimeout(() => (this.ready = this.connect()), RECONNECT_MS);
      });
    });
  }

  private onMessage(text: string): void {
    const message = JSON.parse(text) as TerminalMessage;
    if (message.type === "values") {
      this.onRows?.(message.rows ?? []);
    } else if (message.type === "written") {
      this.queue.shift()?.resolve(message.value);
    } else if (message.type === "error") {
      // Errors answer the oldest request; with none pending they concern the monitoring.
      const pending = this.queue.shift();
      if (pending) pending.reject(new Error(message.detail ?? "error"));
      else this.onError?.(message.detail ?? "error");
    }
  }

  private async send(message: unknown): Promise<void> {
    await this.ready;
    this.socket?.send(JSON.stringify(message));
  }

  /** Start (or replace) continuous monitoring; an empty list stops it. */
  watch(items: WatchItem[], periodMs: number): void {
    this.watchMessage = { op: "watch", items, period_ms: periodMs };
    void this.send(this.watchMessage);
  }

  write(item: WatchItem, value: number | string, physical: boolean): Promise<ObjectValue> {
    return new Promise((resolve, reject) => {
      this.queue.push({ resolve: resolve as (value: unknown) => void, reject });
      void this.send({ op: "write", ...item, value, physical, client: getMotionClient() });
    });
  }

  close(): void {
    this.closed = true;
    this.socket?.close();
  }
}
