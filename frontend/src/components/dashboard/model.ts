/**
 * The dashboard's live state and its actions, for the components to bind to and call: the status word (from REST
 * first, then the server's terminal socket, which samples every 200 ms), NMT state, faults (fetched again when
 * status word bit 3 or 7 changes or an EMCY of the node arrives), the live value of every watched entry, and the
 * commands (state transitions, mode, NMT, quick test), each guarded so a refusal shows in the message line.
 */

import { projectAddress } from "../../client/api";
import { controlApi, heldByMe, type AxisControl } from "../../client/control";
import { driveApi, serverBus, type FaultReport, type ObjectValue } from "../../client/drives";
import { TerminalSocket, type WatchRow } from "../../client/terminal-socket";
import { confirmAction, errorText, toast } from "../ui";
import { COMMAND_LABELS, type Command } from "../../lib/cia402";
import { PROFILE_VELOCITY_MODE, type DashboardSignals } from "../../lib/dashboard-objects";
import { Scope, batch, derive, state, type State } from "../../lib/dom";
import type { Entry, Scalar } from "../../lib/od";
import type { AxisContext } from "../../pages/axis";
import type { DashboardMessage } from "./notice";
import type { QuickTestValue } from "./quick-test";

export const LIVE_PERIOD_MS = 200;
const MAX_WATCHED = 32;
/** Status word bits 3 (fault) and 7 (warning): a change fetches the faults again. */
const FAULT_BITS = 0x88;

/** Target state of each command for the server's state walk (PUT …/state). */
const COMMAND_TARGETS: Record<Exclude<Command, "fault_reset">, string> = {
  shutdown: "ready-to-switch-on",
  switch_on: "switched-on",
  enable_operation: "operation-enabled",
  disable_operation: "switched-on",
  disable_voltage: "switch-on-disabled",
  quick_stop: "quick-stop-active",
};

/** The last sample of a watched entry; a failed sample keeps the last value and says why. */
export interface LiveCell {
  value?: ObjectValue;
  error?: string;
}

export class DashboardModel {
  readonly statusword = state<number | null>(null);
  readonly nmt = state("");
  readonly busy = state(false);
  readonly connection = state("");
  readonly message = state<DashboardMessage | null>(null);
  readonly faults = state<FaultReport | string | null>(null);
  /** Who holds the axis (docs/motion-safety.md); null until the server answered. */
  readonly control = state<AxisControl | null>(null);
  /** Who asked this page, the controller, for the axis. */
  readonly askedBy = state<string | null>(null);
  /** False once the first answer came and the live hub says the drive is offline. */
  readonly reachable: State<boolean>;
  private readonly answered = state(false);
  private readonly hubOnline: State<boolean>;
  private readonly cells = new Map<string, State<LiveCell>>();
  private readonly quickValues = new Map<Entry, State<Scalar>>();
  private readonly terminal = new TerminalSocket();
  private readonly bus: string;
  private readonly node: number;
  private faultKey = "";

  constructor(
    private readonly context: AxisContext,
    readonly signals: DashboardSignals,
    scope: Scope,
  ) {
    this.bus = context.axis.bus;
    this.node = context.axis.node_id;
    const live = context.page.app.live;
    this.hubOnline = state(live.axis(this.bus, this.node)?.online ?? false);
    this.reachable = scope.run(() => derive(() => !this.answered.val || this.hubOnline.val));
    scope.add(live.onChange(() => (this.hubOnline.val = live.axis(this.bus, this.node)?.online ?? false)));
    scope.add(live.on("nmt_state", (event) => {
      if (this.isOurs(event)) this.nmt.val = `NMT ${String(event.nmt_state)}`;
    }));
    scope.add(live.on("emcy", (event) => {
      if (this.isOurs(event)) void this.refreshFaults();
    }));
    scope.add(live.on("control", (event) => {
      if (!this.isOurs(event)) return;
      this.control.val = { bus: event.bus, node: event.node, holder: event.holder, requests: event.requests };
      if (!heldByMe(this.control.rawVal)) this.askedBy.val = null;
    }));
    scope.add(live.on("control_request", (event) => {
      if (this.isOurs(event)) this.askedBy.val = event.from.user;
    }));
    scope.add(live.on("ws_open", () => void this.refreshControl()));
    this.terminal.onRows = (rows) => this.onRows(rows);
    this.terminal.onError = (text) => (this.message.val = { kind: "error", text });
    this.terminal.onConnection = (open) => (this.connection.val = open ? `live · every ${LIVE_PERIOD_MS} ms` : "live data reconnecting…");
    scope.add(() => this.terminal.close());
  }

  key(entry: Entry): string {
    return projectAddress(entry.object.index, entry.variable.subindex);
  }

  /** The live value of a watched entry (a state: components read it inside bindings). */
  cell(entry: Entry): State<LiveCell> {
    return this.cellOf(this.key(entry));
  }

  /** The drive's value of a quick-test field, read once when the page opens. */
  quickValue(entry: Entry): State<Scalar> {
    let value = this.quickValues.get(entry);
    if (!value) {
      const created = (value = state<Scalar>(null));
      this.quickValues.set(entry, created);
      void driveApi.read(this.bus, this.node, this.key(entry)).then((answer) => (created.val = answer.raw)).catch(() => undefined);
    }
    return value;
  }

  /**
   * The state comes from REST first (the page shows at once and fills in); the live watch starts after it, when the
   * server knows the node's device and the project bus's server id is known.
   */
  async start(): Promise<void> {
    const live = this.context.page.app.live;
    try {
      const answer = await driveApi.state(this.bus, this.node);
      live.updateAxis(this.bus, this.node, { online: true, nmt: answer.nmt_state });
      // The node's own heartbeat state, else what its SDO answer proves (pre-operational or operational); a
      // PROFIBUS-DP drive has no NMT, and the server leaves the fields out.
      const noNmt = answer.nmt_state === undefined && answer.nmt_text === undefined;
      this.nmt.val = noNmt ? "no NMT (PROFIBUS-DP)" : `NMT ${answer.nmt_text || (answer.nmt_state ?? "unknown")}`;
      this.applyStatusword(answer.statusword);
    } catch (error) {
      live.updateAxis(this.bus, this.node, { online: false });
      this.nmt.val = "NMT —";
      const projectBus = this.context.project.buses.find((candidate) => candidate.name === this.bus);
      this.message.val = { kind: "offline", text: `Drive not reachable: ${errorText(error)}`, bus: projectBus ?? null };
    }
    this.answered.val = true;
    void this.refreshControl();
    const { statusword, modeDisplay, measurements, inputs, outputs } = this.signals;
    const watched = [statusword, modeDisplay, ...measurements, inputs, outputs].filter((entry): entry is Entry => entry !== null);
    this.terminal.watch(watched.slice(0, MAX_WATCHED).map((entry) => ({ bus: serverBus(this.bus), node: this.node, object: this.key(entry) })), LIVE_PERIOD_MS);
  }

  /** Run a command; its refusal shows in the message line. True when it succeeded. */
  async guard(label: string, work: () => Promise<void>): Promise<boolean> {
    this.busy.val = true;
    this.message.val = null;
    try {
      await work();
      return true;
    } catch (error) {
      this.message.val = { kind: "error", text: `${label}: ${errorText(error)}`, testid: "dashboard-error" };
      return false;
    } finally {
      this.busy.val = false;
    }
  }

  /** The caller may take an axis over from its controller (Expert and above). */
  mayTakeOver(): boolean {
    const level = this.context.page.app.live.user()?.level;
    return level === "expert" || level === "administrator";
  }

  arm(): Promise<boolean> {
    return this.guard("Arm", async () => void (this.control.val = await controlApi.arm(this.bus, this.node)));
  }

  release(): Promise<boolean> {
    return this.guard("Release", async () => {
      this.control.val = await controlApi.release(this.bus, this.node);
      this.askedBy.val = null;
    });
  }

  request(): Promise<boolean> {
    return this.guard("Ask for the axis", async () => {
      this.control.val = await controlApi.request(this.bus, this.node);
      toast(`${this.control.rawVal?.holder?.user ?? "The controller"} was asked to release the axis`, "info");
    });
  }

  async takeOver(): Promise<boolean> {
    const holder = this.control.rawVal?.holder;
    const text = `${holder?.user ?? "Another client"} holds this axis. Taking it over makes this page its controller at once (logged); the axis keeps its state.`;
    if (!(await confirmAction("Take over the axis", text, "Take over", true))) return false;
    return this.guard("Take over", async () => void (this.control.val = await controlApi.takeOver(this.bus, this.node)));
  }

  runCommand(command: Command): Promise<boolean> {
    return this.guard(COMMAND_LABELS[command], async () => {
      if (command === "fault_reset") {
        this.showFaults(await driveApi.resetFaults(this.bus, this.node));
        this.applyStatusword((await driveApi.state(this.bus, this.node)).statusword);
        return;
      }
      this.applyStatusword((await driveApi.setState(this.bus, this.node, COMMAND_TARGETS[command])).statusword);
    });
  }

  setMode(raw: number, label: string): Promise<boolean> {
    return this.guard("Mode of operation", async () => {
      if (!this.signals.mode) return;
      await driveApi.writeKey(this.bus, this.node, this.key(this.signals.mode), raw);
      toast(`Mode of operation set to ${label}`, "ok");
    });
  }

  sendNmt(command: string, label: string): Promise<boolean> {
    return this.guard(`NMT ${label}`, () => driveApi.nmt(this.bus, command, this.node));
  }

  openBus(bus: { name: string; interface: string }): Promise<boolean> {
    const { page, project, axis } = this.context;
    return this.guard(`Open bus ${bus.name}`, async () => {
      await driveApi.openBus(bus.interface, bus.name);
      await page.app.refreshBuses();
      page.app.navigate({ page: "axis", project: project.name, axis: axis.name, view: "dashboard" }, {}, true);
    });
  }

  /** Profile velocity: mode 3, then the ramps and the target, each through the server's checks. */
  runQuickTest(values: QuickTestValue[]): Promise<boolean> {
    return this.guard("Quick test", async () => {
      await driveApi.writeKey(this.bus, this.node, this.key(this.signals.mode!), PROFILE_VELOCITY_MODE);
      for (const { entry, raw } of values) await driveApi.writeKey(this.bus, this.node, this.key(entry), raw);
      const target = values.find((value) => value.entry === this.signals.targetVelocity);
      toast(`Profile velocity: target ${target?.text} ${this.signals.targetVelocity?.variable.unit}`, "ok");
    });
  }

  stopQuickTest(): Promise<boolean> {
    return this.guard("Quick test", async () => {
      const target = this.signals.targetVelocity!;
      await driveApi.writeKey(this.bus, this.node, this.key(target), 0);
      this.quickValue(target).val = 0;
    });
  }

  refuse(label: string, reason: string): void {
    this.message.val = { kind: "error", text: `${label}: ${reason}`, testid: "dashboard-error" };
  }

  private async refreshControl(): Promise<void> {
    try {
      this.control.val = await controlApi.get(this.bus, this.node);
    } catch {
      this.control.val = null; // the bus is not open: the dashboard says so already
    }
  }

  private cellOf(key: string): State<LiveCell> {
    let cell = this.cells.get(key);
    if (!cell) this.cells.set(key, (cell = state<LiveCell>({})));
    return cell;
  }

  private isOurs(event: { bus: unknown; node: unknown }): boolean {
    return event.bus === serverBus(this.bus) && event.node === this.node;
  }

  private applyStatusword(word: number): void {
    const previous = this.statusword.rawVal;
    this.statusword.val = word;
    this.context.page.app.live.updateAxis(this.bus, this.node, { online: true, statusword: word });
    if (previous === null || (previous & FAULT_BITS) !== (word & FAULT_BITS)) void this.refreshFaults();
  }

  private onRows(rows: WatchRow[]): void {
    batch(() => {
      for (const row of rows) {
        const cell = this.cellOf(row.object);
        if (row.value) cell.val = { value: row.value };
        else if (row.error) cell.val = { value: cell.rawVal.value, error: row.error };
      }
    });
    const entry = this.signals.statusword;
    if (!entry) return;
    const sample = this.cell(entry).rawVal;
    const raw = sample.value?.raw;
    if (typeof raw === "number" && raw !== this.statusword.rawVal) this.applyStatusword(raw);
    if (sample.error && !sample.value) this.context.page.app.live.updateAxis(this.bus, this.node, { online: false });
  }

  private showFaults(report: FaultReport): void {
    this.faultKey = JSON.stringify([report.faults, report.warnings, report.error_code]);
    this.faults.val = report;
    const firstFault = report.faults[0]?.name ?? (report.fault ? report.error_text : "");
    this.context.page.app.live.updateAxis(this.bus, this.node, { faultText: firstFault });
  }

  private async refreshFaults(): Promise<void> {
    try {
      const report = await driveApi.faults(this.bus, this.node);
      if (JSON.stringify([report.faults, report.warnings, report.error_code]) !== this.faultKey) this.showFaults(report);
    } catch (error) {
      this.faults.val = errorText(error);
    }
  }
}
