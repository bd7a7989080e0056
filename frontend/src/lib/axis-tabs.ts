/**
 * The tabs of an axis and which of them its device can use, from the services the server says the device has (the
 * dictionary's `features`: scope, current_loop, phasing, auto_tuning, frequency_response, sequences, io), never from
 * a list of device names:
 * a TTA-PRO (PROFIBUS-DP) has none of them, so its axis shows the dashboard, parameters, checklist and backup only.
 * A tab without a feature works on every device.
 */

import type { Dictionary } from "./od";
import type { AxisView } from "./router";

export interface AxisTab {
  view: AxisView;
  label: string;
  /** Its keyboard shortcut, "" when it has none. */
  keys: string;
  /** The feature the device needs for it. */
  feature?: string;
}

export const AXIS_TABS: readonly AxisTab[] = [
  { view: "dashboard", label: "Dashboard", keys: "g d" },
  { view: "parameters", label: "Parameters", keys: "g p" },
  { view: "commissioning", label: "Commissioning", keys: "g c" },
  { view: "backup", label: "Backup / restore", keys: "g k" },
  { view: "scope", label: "Scope", keys: "g s", feature: "scope" },
  { view: "current-loop", label: "Current loop", keys: "", feature: "current_loop" },
  { view: "phasing", label: "Phasing", keys: "", feature: "phasing" },
  { view: "tuning", label: "Auto-tuning", keys: "", feature: "auto_tuning" },
  { view: "bode", label: "Bode / what-if", keys: "", feature: "frequency_response" },
  { view: "sequences", label: "Sequences", keys: "", feature: "sequences" },
  { view: "io", label: "I/O", keys: "", feature: "io" },
];

/** The tabs the device can use, in their order. */
export function axisTabs(dictionary: Pick<Dictionary, "features">): AxisTab[] {
  return AXIS_TABS.filter((tab) => !tab.feature || dictionary.features.includes(tab.feature));
}

/** The tab of a view (every view has one). */
export function axisTab(view: AxisView): AxisTab {
  return AXIS_TABS.find((tab) => tab.view === view)!;
}
