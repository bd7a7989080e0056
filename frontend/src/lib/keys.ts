/**
 * Keyboard shortcuts: single keys and two-key sequences ("g d"), as in many web tools. The matcher is pure so the
 * sequences are unit-tested; `shortcuts.ts` connects it to the document.
 */

export interface Binding {
  keys: string;
  action: string;
  description: string;
}

export const BINDINGS: Binding[] = [
  { keys: "/", action: "focus-search", description: "Focus the search field of the page" },
  { keys: "?", action: "help", description: "Show or hide this list" },
  { keys: "g h", action: "go-home", description: "Projects" },
  { keys: "g d", action: "go-dashboard", description: "Dashboard of the current axis" },
  { keys: "g p", action: "go-parameters", description: "Parameters of the current axis" },
  { keys: "g c", action: "go-commissioning", description: "Commissioning checklist of the current axis" },
  { keys: "g k", action: "go-backup", description: "Backup / restore of the current axis" },
  { keys: "g s", action: "go-scope", description: "Scope of the current axis" },
  { keys: "g l", action: "go-current-loop", description: "Current loop of the current axis" },
  { keys: "g f", action: "go-phasing", description: "Phasing of the current axis" },
  { keys: "g u", action: "go-tuning", description: "Auto-tuning of the current axis" },
  { keys: "g b", action: "go-bus", description: "Bus: connect and scan" },
  { keys: "g t", action: "go-terminal", description: "Dialog terminal" },
  { keys: "g o", action: "go-dictionaries", description: "Object dictionaries" },
  { keys: "g m", action: "go-motors", description: "Motor catalog" },
  { keys: "[", action: "previous-axis", description: "Previous axis of the project" },
  { keys: "]", action: "next-axis", description: "Next axis of the project" },
  { keys: "T", action: "toggle-theme", description: "Switch between light and dark theme" },
  { keys: "a", action: "scope-arm", description: "Scope: arm the recorder" },
  { keys: "f", action: "scope-force", description: "Scope: force the trigger" },
  { keys: "s", action: "scope-stop", description: "Scope: stop the recorder" },
  { keys: "Escape", action: "escape", description: "Close a dialog or this list; leave a field" },
];

export const SEQUENCE_TIMEOUT_MS = 1200;

/** Feeds key presses and reports the action of a completed binding, keeping the prefix of a pending sequence. */
export class KeyMatcher {
  private pending = "";
  private pendingSince = 0;

  constructor(private readonly bindings: readonly Binding[] = BINDINGS) {}

  feed(key: string, now: number): string | null {
    if (this.pending && now - this.pendingSince > SEQUENCE_TIMEOUT_MS) this.pending = "";
    const candidate = this.pending ? `${this.pending} ${key}` : key;
    const exact = this.bindings.find((binding) => binding.keys === candidate);
    if (exact) {
      this.pending = "";
      return exact.action;
    }
    if (this.bindings.some((binding) => binding.keys.startsWith(candidate + " "))) {
      this.pending = candidate;
      this.pendingSince = now;
      return null;
    }
    this.pending = "";
    // A wrong second key starts over: "g x d" is not "g d", but "x" then "/" still focuses search.
    return candidate === key ? null : this.feed(key, now);
  }

  reset(): void {
    this.pending = "";
  }
}
