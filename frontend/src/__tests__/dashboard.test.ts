import { describe, expect, it, vi } from "vitest";
import type { FaultReport, ObjectValue } from "../client/drives";
import { deviceControl, type DeviceControlProps } from "../components/dashboard/device-control";
import { faultsPanel } from "../components/dashboard/faults";
import { digitalIo, shortName } from "../components/dashboard/io";
import { measurementsPanel } from "../components/dashboard/measurements";
import type { LiveCell } from "../components/dashboard/model";
import { dashboardNotice, type DashboardMessage } from "../components/dashboard/notice";
import { quickTest } from "../components/dashboard/quick-test";
import { statusWordPanel } from "../components/dashboard/status-word";
import { state, type State } from "../lib/dom";
import type { Entry, Scalar } from "../lib/od";
import { choose, entry, type } from "./fixtures";

const testid = (root: HTMLElement, id: string) => root.querySelector<HTMLElement>(`[data-testid="${id}"]`);
const click = (element: Element | null) => (element as HTMLElement).click();
const sample = (raw: number): LiveCell => ({ value: { raw } as ObjectValue });

const mode = entry(0x6060, { name: "Modes of operation", data_type: "INTEGER8", enum: { "1": "Profile position", "3": "Profile velocity" } });

function control(overrides: Partial<DeviceControlProps> = {}) {
  const props = {
    statusword: state<number | null>(null), reachable: state(true), busy: state(false), armed: state(true), nmt: state("NMT OPERATIONAL"),
    connection: state(""), mode, nmtCommands: true, modes: true, activeMode: state<Scalar>(3), activeModeText: state("Profile velocity (3)"),
    onCommand: vi.fn(), onSetMode: vi.fn(), onNmt: vi.fn(), ...overrides,
  };
  return { props, element: deviceControl(props) };
}

const buttons = (element: HTMLElement) => [...testid(element, "dashboard-transitions")!.querySelectorAll("button")];

describe("device control", () => {
  it("says why there is no state yet: reading, or the drive does not answer", () => {
    const { props, element } = control();
    expect(testid(element, "dashboard-state")!.textContent).toBe("—");
    expect(testid(element, "dashboard-transitions")!.textContent).toBe("Reading the state…");
    props.reachable.val = false;
    expect(testid(element, "dashboard-transitions")!.textContent).toContain("The drive does not answer");
  });

  it("shows the state of the status word and follows it, with the transitions it allows", () => {
    const { props, element } = control();
    props.statusword.val = 0x0240;
    expect(testid(element, "dashboard-state")!.textContent).toBe("Switch on disabled");
    expect(testid(element, "dashboard-statusword")!.textContent).toBe("0x0240");
    expect(element.querySelector(".led.on")!.textContent).toBe("SOD");
    expect(buttons(element).map((button) => button.dataset.testid)).toEqual(["transition-shutdown"]);
    props.statusword.val = 0x0227;
    expect(testid(element, "dashboard-state")!.className).toBe("state-name ok");
    expect(buttons(element).map((button) => button.textContent)).toEqual(["Disable operation", "Shutdown", "Disable voltage", "Quick stop"]);
    props.statusword.val = 0x0208;
    expect(testid(element, "dashboard-state")!.className).toBe("state-name bad");
    expect(buttons(element).map((button) => button.dataset.testid)).toEqual(["transition-fault_reset"]);
  });

  it("keeps its buttons while only other status bits change, and disables them while busy", () => {
    const { props, element } = control({ statusword: state<number | null>(0x0221) });
    const before = buttons(element);
    props.statusword.val = 0x0621; // target reached: same state
    expect(buttons(element)).toEqual(before);
    expect(before.every((button) => !button.disabled)).toBe(true);
    props.busy.val = true;
    expect(before.every((button) => button.disabled)).toBe(true);
  });

  it("keeps Enable operation disabled until this page armed the axis, and says why", () => {
    const armed = state(false);
    const { element } = control({ statusword: state<number | null>(0x0223), armed });
    const enable = testid(element, "transition-enable_operation") as HTMLButtonElement;
    expect(enable.disabled).toBe(true);
    expect(enable.title).toContain("Arm the axis first");
    expect((testid(element, "transition-shutdown") as HTMLButtonElement).disabled).toBe(false);
    armed.val = true;
    expect(enable.disabled).toBe(false);
  });

  it("calls the command of a clicked transition and the NMT command of a clicked button", () => {
    const { props, element } = control({ statusword: state<number | null>(0x0223) });
    click(testid(element, "transition-enable_operation"));
    expect(props.onCommand).toHaveBeenCalledWith("enable_operation");
    click([...element.querySelectorAll("button")].find((button) => button.textContent === "Reset node")!);
    expect(props.onNmt).toHaveBeenCalledWith("reset-node", "Reset node");
  });

  it("shows the active mode, follows it in the selector until a mode is picked, and sets the picked one", () => {
    const activeMode = state<Scalar>(3);
    const { props, element } = control({ activeMode });
    const select = testid(element, "dashboard-mode-select") as HTMLSelectElement;
    expect(testid(element, "dashboard-mode")!.textContent).toBe("Profile velocity (3)");
    expect(select.value).toBe("3");
    activeMode.val = 0;
    expect(select.selectedOptions[0].text).toBe("0 (no mode)");
    choose(select, "1");
    activeMode.val = 3;
    expect(select.value).toBe("1");
    click(testid(element, "dashboard-set-mode"));
    expect(props.onSetMode).toHaveBeenCalledWith(1, "Profile position (1)");
  });

  it("offers no NMT commands and no mode of operation to a device without them (PROFIBUS-DP)", () => {
    const { element } = control({ nmtCommands: false, modes: false, mode: null });
    expect(testid(element, "dashboard-nmt-commands")).toBeNull();
    expect(testid(element, "dashboard-mode")).toBeNull();
    expect(element.textContent).not.toContain("Mode of operation");
    expect(testid(control().element, "dashboard-nmt-commands")!.querySelectorAll("button")).toHaveLength(4);
  });

  it("binds the NMT state and the live connection", () => {
    const { props, element } = control();
    props.nmt.val = "NMT PRE-OPERATIONAL";
    props.connection.val = "live · every 200 ms";
    expect(testid(element, "dashboard-nmt")!.textContent).toBe("NMT PRE-OPERATIONAL");
    expect(element.querySelector("h2")!.textContent).toContain("live · every 200 ms");
  });
});

const report = (overrides: Partial<FaultReport> = {}): FaultReport => ({
  node: 1, state: null, statusword: 0, fault: false, error_code: 0, error_text: "", faults: [], warnings: [], ...overrides,
}) as FaultReport;

describe("faults and warnings", () => {
  it("shows the report, follows a new one, and resets on click", () => {
    const shown = state<FaultReport | string | null>(null);
    const onReset = vi.fn();
    const element = faultsPanel({ report: shown, onReset });
    expect(testid(element, "dashboard-faults")!.textContent).toBe("");
    shown.val = report();
    expect(testid(element, "no-faults")!.textContent).toBe("No fault, no warning.");
    shown.val = report({
      fault: true,
      faults: [{ code: 7, cia402_code: 0x2310, name: "Over-current", remedy: "Check the motor wiring" }],
      warnings: [{ code: 2, cia402_code: 0x4210, name: "Temperature", remedy: "" }],
    } as Partial<FaultReport>);
    expect([...element.querySelectorAll(".fault-item .title")].map((title) => title.textContent)).toEqual([
      "Fault 7: Over-current  0x2310", "Warning 2: Temperature  0x4210",
    ]);
    expect(testid(element, "fault-item")!.textContent).toContain("Check the motor wiring");
    shown.val = report({
      fault: true,
      faults: [{ code: 64, cia402_code: 0xffa2, name: "Procedure error", remedy: "" }],
      causes: [{ object: "0x6410,11 Motor data.Torque constant", value: 0, problem: "is 0", needed_by: "auto-tuning" }],
    } as Partial<FaultReport>);
    expect(testid(element, "fault-cause")!.textContent).toBe(
      "Likely cause: 0x6410,11 Motor data.Torque constant is 0auto-tuning needs it: set it, then start again.");
    shown.val = report({ fault: true, error_code: 0x5530, error_text: "EEPROM" });
    expect(testid(element, "fault-item")!.textContent).toBe("Fault: EEPROM  0x5530");
    shown.val = "no answer";
    expect(element.querySelector(".error-text")!.textContent).toBe("no answer");
    click(testid(element, "fault-reset"));
    expect(onReset).toHaveBeenCalledOnce();
  });
});

const statusword = entry(0x6041, { name: "Statusword", bits: [
  { first: 0, last: 0, name: "Ready to switch on" }, { first: 2, last: 2, name: "Operation enabled" }, { first: 3, last: 3, name: "Fault" },
] });

describe("status word", () => {
  it("shows nothing until the word is known, then each bit, following the word", () => {
    const word = state<number | null>(null);
    const element = statusWordPanel({ entry: statusword, address: "0x6041,0", statusword: word });
    const bits = testid(element, "dashboard-sw-bits")!;
    expect(bits.children).toHaveLength(0);
    word.val = 0x05;
    expect([...bits.querySelectorAll("div.set[title]")].map((cell) => cell.textContent)).toEqual(["● Ready to switch on", "● Operation enabled"]);
    word.val = 0x08;
    expect([...bits.querySelectorAll("div.set[title]")].map((cell) => cell.textContent)).toEqual(["● Fault"]);
    expect(element.querySelector("h2")!.textContent).toContain("0x6041,0");
  });
});

describe("digital I/O", () => {
  const inputs = entry(0x60fd, { name: "Digital inputs", data_type: "UNSIGNED32", bits: [
    { first: 0, last: 0, name: "Negative limit switch" }, { first: 16, last: 16, name: "IN1 (digital input 1)" },
  ] });

  it("lights the LEDs of the set bits of the live word and follows it", () => {
    const cell = state<number | null>(null);
    const element = digitalIo({ inputs, outputs: null, word: () => cell.val, address: () => "0x60FD,0" });
    const leds = (row: string) => [...testid(element, row)!.querySelectorAll(".led")].map((led) => `${led.textContent}${led.classList.contains("on") ? "*" : ""}`);
    expect([leds("io-inputs"), leds("io-inputs-functions")]).toEqual([["IN1"], ["LIM−"]]);  // terminals; what the drive makes of them
    cell.val = 0x10001;
    expect([leds("io-inputs"), leds("io-inputs-functions")]).toEqual([["IN1*"], ["LIM−*"]]);
    expect(element.textContent).toContain("Inputs · 0x60FD,0 = 0x00010001");
    expect(testid(element, "io-outputs")).toBeNull();
  });

  it("says so when the dictionary has no I/O, and shortens bit names", () => {
    expect(digitalIo({ inputs: null, outputs: null, word: () => null, address: () => "" }).textContent).toContain("no digital I/O objects");
    expect([shortName("OUT 3"), shortName("Positive limit switch"), shortName("Home switch")]).toEqual(["OUT3", "LIM+", "Home"]);
  });
});

describe("measurements", () => {
  it("shows each live value in its unit, an error with its reason, and follows the samples", () => {
    const voltage = entry(0x6079, { name: "DC link circuit voltage", unit: "V", scale: 0.1, access: "ro" });
    const cells = new Map<Entry, State<LiveCell>>([[voltage, state<LiveCell>({})]]);
    const element = measurementsPanel({ entries: [voltage], cell: (item) => cells.get(item)!.val, address: () => "0x6079,0" });
    const value = testid(element, "readout-0x6079,0")!.querySelector<HTMLElement>(".value")!;
    expect(value.textContent).toBe("");
    cells.get(voltage)!.val = sample(3255);
    expect(value.textContent).toBe("325.5");
    cells.get(voltage)!.val = { ...sample(3255), error: "SDO timeout" };
    expect([value.textContent, value.title]).toEqual(["error", "SDO timeout"]);
    expect(testid(element, "readout-0x6079,0")!.textContent).toContain("DC link circuit voltage");
  });

  it("shows a current monitor at a readable precision, not ten digits", () => {
    const scaled = entry(0x3000, { name: "Current monitor", data_type: "INTEGER16", unit: "A", scale: 0.0061038881767686015, access: "ro" });
    const real = entry(0x3001, { name: "Current", data_type: "REAL32", unit: "A", access: "ro" });
    const cells = new Map<Entry, State<LiveCell>>([[scaled, state<LiveCell>(sample(127))], [real, state<LiveCell>(sample(0.7782819016))]]);
    const element = measurementsPanel({ entries: [scaled, real], cell: (item) => cells.get(item)!.val, address: (item) => item.key });
    const shown = (item: Entry) => testid(element, `readout-${item.key}`)!.querySelector<HTMLElement>(".value")!.textContent;
    expect([shown(scaled), shown(real)]).toEqual(["0.775", "0.77828"]);
  });
});

describe("quick test", () => {
  const target = entry(0x60ff, { name: "Target velocity", data_type: "INTEGER32", unit: "rpm" });
  const acceleration = entry(0x6083, { name: "Profile acceleration", data_type: "UNSIGNED32", unit: "rpm/s" });

  function panel() {
    const values = new Map<Entry, State<Scalar>>([[target, state<Scalar>(0)], [acceleration, state<Scalar>(null)]]);
    const props = {
      acceleration, deceleration: null, target, value: (item: Entry) => values.get(item)!,
      onRun: vi.fn(), onStop: vi.fn(async () => true), onRefuse: vi.fn(),
    };
    return { values, props, element: quickTest(props) };
  }

  it("shows the drive's values once read and runs with the typed ones", () => {
    const { values, props, element } = panel();
    const accel = testid(element, "qt-acceleration") as HTMLInputElement;
    expect(accel.value).toBe("");
    values.get(acceleration)!.val = 5000;
    expect(accel.value).toBe("5000");
    expect(element.textContent).toContain("Target velocity [rpm]");
    type(testid(element, "qt-velocity") as HTMLInputElement, "1500");
    click(testid(element, "qt-run"));
    expect(props.onRun).toHaveBeenCalledWith([
      { entry: acceleration, raw: 5000, text: "5000" }, { entry: target, raw: 1500, text: "1500" },
    ]);
  });

  it("refuses a field it cannot parse with the field's name, running nothing", () => {
    const { props, element } = panel();
    type(testid(element, "qt-velocity") as HTMLInputElement, "2,5");
    click(testid(element, "qt-run"));
    expect(props.onRefuse).toHaveBeenCalledWith('Profile acceleration: enter a number');
    type(testid(element, "qt-acceleration") as HTMLInputElement, "100");
    click(testid(element, "qt-run"));
    expect(props.onRefuse).toHaveBeenLastCalledWith('Target velocity: "2,5": use "." as decimal separator');
    expect(props.onRun).not.toHaveBeenCalled();
  });

  it("has no profile velocity fields without a target velocity (a TTA-PRO: motions only)", () => {
    const element = quickTest({ ...panel().props, target: null });
    expect([testid(element, "qt-run"), testid(element, "qt-velocity")]).toEqual([null, null]);
  });

  it("shows the target the drive holds again after Stop", async () => {
    const { values, props, element } = panel();
    const velocity = testid(element, "qt-velocity") as HTMLInputElement;
    type(velocity, "2000");
    values.get(target)!.val = 0;
    expect(velocity.value).toBe("2000");
    click(testid(element, "qt-stop"));
    await vi.waitFor(() => expect(velocity.value).toBe("0"));
    expect(props.onStop).toHaveBeenCalledOnce();
  });
});

describe("message line", () => {
  it("shows a refusal or the offline notice with its Open bus button", () => {
    const message = state<DashboardMessage | null>(null);
    const onOpenBus = vi.fn();
    const element = dashboardNotice({ message, onOpenBus });
    expect(element.textContent).toBe("");
    message.val = { kind: "error", text: "Shutdown: refused", testid: "dashboard-error" };
    expect(testid(element, "dashboard-error")!.textContent).toBe("Shutdown: refused");
    message.val = { kind: "offline", text: "Drive not reachable", bus: { name: "can", interface: "socketcan:can0" } };
    click(testid(element, "dashboard-offline")!.querySelector("button"));
    expect(onOpenBus).toHaveBeenCalledWith({ name: "can", interface: "socketcan:can0" });
    message.val = null;
    expect(element.textContent).toBe("");
  });
});
