/**
 * Axis dashboard: device control (CiA 402 state, allowed transitions, mode of operation, NMT), faults and
 * warnings, the quick test (profile velocity, hold-to-run jog, moves and homing), measurements, the status word bit by bit and the digital I/O — each a
 * component of `components/dashboard/` bound to the page's `DashboardModel` (live values from the server's terminal
 * socket: it samples, this page renders).
 */

import { controllerPanel } from "../components/dashboard/controller";
import { deviceControl } from "../components/dashboard/device-control";
import { faultsPanel } from "../components/dashboard/faults";
import { digitalIo } from "../components/dashboard/io";
import { measurementsPanel } from "../components/dashboard/measurements";
import { DashboardModel } from "../components/dashboard/model";
import { dashboardNotice } from "../components/dashboard/notice";
import { phasingNotice } from "../components/dashboard/phasing-notice";
import { quickTest } from "../components/dashboard/quick-test";
import { QuickMotion } from "../components/motion/model";
import { statusWordPanel } from "../components/dashboard/status-word";
import { heldByMe } from "../client/control";
import { dashboardSignals } from "../lib/dashboard-objects";
import { buildPath } from "../lib/router";
import { ioApi } from "../client/io";
import { Scope, h, state } from "../lib/dom";
import { ioNames, type IoNames } from "../lib/io-names";
import type { Entry } from "../lib/od";
import { formatValue } from "../lib/values";
import type { AxisContext, AxisViewPage } from "./axis";

export async function dashboardView(context: AxisContext): Promise<AxisViewPage> {
  const scope = new Scope();
  const model = scope.run(() => new DashboardModel(context, dashboardSignals(context.dictionary), scope));
  const motion = scope.run(() => quickMotion(context, scope));
  const element = scope.run(() => layout(model, context, motion));
  void model.start();
  void motion.load();
  return { element, dispose: () => scope.dispose() };
}

function quickMotion(context: AxisContext, scope: Scope): QuickMotion {
  const { axis, page } = context;
  return new QuickMotion({ bus: axis.bus, node: axis.node_id, device: axis.device, live: page.app.live, scope });
}

function layout(model: DashboardModel, context: AxisContext, motion: QuickMotion): HTMLElement {
  const columns = (template: string, ...children: (HTMLElement | null)[]) =>
    h("div", { class: "grid", style: { gridTemplateColumns: template } }, children);
  return h("div", { class: "page" },
    dashboardNotice({ message: model.message, onOpenBus: (bus) => void model.openBus(bus) }),
    motorPhasingNotice(model, context),
    columns("minmax(0, 1.35fr) minmax(0, 1fr)",
      control(model),
      h("div", { class: "grid", style: { alignContent: "start" } },
        controllerPanel({
          control: model.control, askedBy: model.askedBy, busy: model.busy, mayTakeOver: () => model.mayTakeOver(),
          onArm: () => void model.arm(), onRelease: () => void model.release(),
          onRequest: () => void model.request(), onTakeOver: () => void model.takeOver(),
        }),
        faultsPanel({ report: model.faults, onReset: () => void model.runCommand("fault_reset") }),
        quickTestPanel(model, motion))),
    measurementsPanel({ entries: model.signals.measurements, cell: (entry) => model.cell(entry).val, address: (entry) => model.key(entry) }),
    columns("minmax(0, 1fr) minmax(0, 1fr)",
      statusWordPanel({
        entry: model.signals.statusword, statusword: model.statusword,
        address: model.signals.statusword ? model.key(model.signals.statusword) : "",
      }),
      digitalIo({
        inputs: model.signals.inputs, outputs: model.signals.outputs, word: (entry) => liveWord(model, entry), address: (entry) => model.key(entry),
        names: ioNamesOf(context),
      })));
}

/** The names the axis's I/O configuration gives its inputs and outputs (docs/io.md), once read; none on failure. */
function ioNamesOf(context: AxisContext): () => IoNames | null {
  const names = state<IoNames | null>(null);
  void ioApi.read(context.axis.bus, context.axis.node_id).then((config) => (names.val = ioNames(config))).catch(() => undefined);
  return () => names.val;
}

function control(model: DashboardModel): HTMLElement {
  const display = model.signals.modeDisplay;
  const active = () => (display ? model.cell(display).val.value?.raw : undefined);
  return deviceControl({
    statusword: model.statusword, reachable: model.reachable, busy: model.busy, nmt: model.nmt, connection: model.connection,
    armed: () => heldByMe(model.control.val),
    mode: model.signals.mode,
    nmtCommands: model.signals.nmt,
    modes: Boolean(model.signals.mode || display),
    activeMode: () => {
      const raw = active();
      return typeof raw === "number" ? raw : null;
    },
    activeModeText: () => {
      const raw = active();
      return display && raw !== undefined ? formatValue(display.variable, raw) : "";
    },
    onCommand: (command) => void model.runCommand(command),
    onSetMode: (raw, label) => void model.setMode(raw, label),
    onNmt: (command, label) => void model.sendNmt(command, label),
  });
}

/**
 * The quick test: the hold-to-run motions of every device, and profile velocity when the dictionary has a target
 * velocity and a mode of operation (a TTA-PRO has neither: it jogs, moves and homes through its control word).
 */
function quickTestPanel(model: DashboardModel, motion: QuickMotion): HTMLElement {
  const { targetVelocity, acceleration, deceleration, mode } = model.signals;
  const armed = () => heldByMe(model.control.val);
  return quickTest({
    motion: {
      model: motion, armed, busy: model.busy, heldElsewhere: () => Boolean(model.control.val?.holder) && !armed(),
      modes: Boolean(mode), onArm: () => void model.arm(), onRelease: () => void model.release(),
    },
    acceleration, deceleration, target: mode ? targetVelocity : null,
    value: (entry) => model.quickValue(entry),
    onRun: (values) => void model.runQuickTest(values),
    onStop: () => model.stopQuickTest(),
    onRefuse: (message) => model.refuse("Quick test", message),
  });
}

function liveWord(model: DashboardModel, entry: Entry): number | null {
  const raw = model.cell(entry).val.value?.raw;
  return typeof raw === "number" ? raw : null;
}

/** Warning bit 30 (motor phasing needed) with its one-click remedy. */
function motorPhasingNotice(model: DashboardModel, context: AxisContext): HTMLElement {
  const { project, axis } = context;
  return phasingNotice({
    live: context.page.app.live,
    where: { bus: axis.bus, node: axis.node_id, project: project.name, axis: axis.name },
    faults: model.faults,
    armed: () => heldByMe(model.control.val),
    phasingHref: buildPath({ page: "axis", project: project.name, axis: axis.name, view: "phasing" }),
  });
}
