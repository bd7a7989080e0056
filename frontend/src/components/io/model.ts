/**
 * The I/O page's state: the drive's configuration as last read or written, the edits not written yet (a change is
 * sent whole, checked whole by the server: nothing is written when any part is refused), the live state polled while
 * the page is open, and the simulated drive's test bench inputs.
 */

import { ioApi, type IoChange, type IoConfig, type IoLive } from "../../client/io";
import { state, type State } from "../../lib/dom";
import { failure, type Message } from "../ui";

export interface LineEdit {
  function?: string;
  inverted?: boolean;
}

const POLL_MS = 300;

export class IoPageModel {
  readonly config: State<IoConfig | null> = state(null);
  readonly live: State<IoLive | null> = state(null);
  readonly inputs: State<ReadonlyMap<string, LineEdit>> = state(new Map());
  readonly outputs: State<ReadonlyMap<string, LineEdit>> = state(new Map());
  readonly settings: State<ReadonlyMap<string, string>> = state(new Map());
  readonly message: State<Message | null> = state(null);
  readonly busy = state(false);
  private timer: ReturnType<typeof setInterval> | null = null;

  constructor(readonly bus: string, readonly node: number) {}

  async load(): Promise<void> {
    this.config.val = await ioApi.read(this.bus, this.node);
  }

  startPolling(): void {
    const poll = () => void ioApi.live(this.bus, this.node).then((live) => (this.live.val = live)).catch(() => undefined);
    poll();
    this.timer = setInterval(poll, POLL_MS);
  }

  stop(): void {
    if (this.timer) clearInterval(this.timer);
    this.timer = null;
  }

  get dirty(): boolean {
    return this.inputs.val.size + this.outputs.val.size + this.settings.val.size > 0;
  }

  editLine(which: "inputs" | "outputs", name: string, edit: LineEdit): void {
    const next = new Map(this[which].rawVal);
    next.set(name, { ...next.get(name), ...edit });
    this[which].val = next;
  }

  editSetting(key: string, value: string): void {
    this.settings.val = new Map(this.settings.rawVal).set(key, value);
  }

  discard(): void {
    this.inputs.val = new Map();
    this.outputs.val = new Map();
    this.settings.val = new Map();
    this.message.val = null;
  }

  change(): IoChange {
    const lines = (edits: ReadonlyMap<string, LineEdit>) => [...edits].map(([name, edit]) => ({ name, ...edit }));
    const settings = Object.fromEntries([...this.settings.rawVal].map(([key, text]) => [key, settingValue(text)]));
    return { inputs: lines(this.inputs.rawVal), outputs: lines(this.outputs.rawVal), settings };
  }

  async write(): Promise<void> {
    await this.guard(async () => {
      const result = await ioApi.change(this.bus, this.node, this.change());
      this.config.val = result;
      this.discard();
      this.message.val = { text: `Written: ${(result.written ?? []).join(", ") || "nothing changed"}`, tone: "ok", testid: "io-message" };
    });
  }

  async setSimInputs(value: number): Promise<void> {
    await this.guard(async () => {
      this.live.val = await ioApi.simInputs(this.bus, this.node, value);
      this.config.val = await ioApi.read(this.bus, this.node); // the findings of the new levels
    });
  }

  private async guard(work: () => Promise<void>): Promise<void> {
    this.busy.val = true;
    try {
      await work();
    } catch (error) {
      this.message.val = failure(error, "io-error");
    } finally {
      this.busy.val = false;
    }
  }
}

/** A setting as typed: a decimal or 0x hex number is sent as a number, anything else as text the server explains. */
export function settingValue(text: string): number | string {
  const trimmed = text.trim();
  if (/^-?\d+$/.test(trimmed)) return Number(trimmed);
  if (/^0x[0-9a-f]+$/i.test(trimmed)) return Number.parseInt(trimmed, 16);
  return trimmed;
}
