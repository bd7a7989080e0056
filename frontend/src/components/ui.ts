/** Small shared widgets: toasts, modal dialogs, progress lines, a panel with a title. */

import { h } from "../lib/dom";

let toastArea: HTMLElement | null = null;

/** A short message in the corner; errors stay until clicked, confirmations fade after a few seconds. */
export function toast(message: string, kind: "ok" | "error" | "info" = "info"): void {
  if (!toastArea || !toastArea.isConnected) {
    toastArea = h("div", { class: "toast-area", role: "status", "aria-live": "polite" });
    document.body.append(toastArea);
  }
  const item = h("div", { class: `toast ${kind}`, "data-testid": "toast", onclick: () => item.remove() }, message);
  toastArea.append(item);
  if (kind !== "error") setTimeout(() => item.remove(), 4000);
}

export interface DialogHandle {
  close(): void;
  body: HTMLElement;
  actions: HTMLElement;
}

/** A modal dialog; Escape or a click beside it closes it (and calls `onClose`). */
export function openDialog(title: string, onClose?: () => void): DialogHandle {
  const body = h("div", { class: "body" });
  const actions = h("div", { class: "actions" });
  const dialog = h("div", { class: "dialog", role: "dialog", "aria-label": title }, h("h2", null, title), body, actions);
  const overlay = h("div", { class: "overlay" }, dialog);
  const close = () => {
    overlay.remove();
    document.removeEventListener("keydown", onKey, true);
    onClose?.();
  };
  const onKey = (event: KeyboardEvent) => {
    if (event.key === "Escape") {
      event.stopPropagation();
      close();
    }
  };
  overlay.addEventListener("mousedown", (event) => {
    if (event.target === overlay) close();
  });
  document.addEventListener("keydown", onKey, true);
  document.body.append(overlay);
  return { close, body, actions };
}

/** Ask before something irreversible (restore, delete, enabling power). Resolves true on confirmation. */
export function confirmAction(title: string, text: string, confirmLabel: string, danger = false): Promise<boolean> {
  return new Promise((resolve) => {
    let answered = false;
    const dialog = openDialog(title, () => {
      if (!answered) resolve(false);
    });
    dialog.body.append(h("p", { style: { margin: "0" } }, text));
    const ok = h("button", { class: danger ? "danger solid" : "primary", "data-testid": "confirm" }, confirmLabel);
    ok.addEventListener("click", () => {
      answered = true;
      dialog.close();
      resolve(true);
    });
    dialog.actions.append(h("button", { onclick: () => dialog.close() }, "Cancel"), ok);
    ok.focus();
  });
}

/** Format an error for the user: the server's message when it has one. */
export function errorText(error: unknown): string {
  return error instanceof Error ? error.message : String(error);
}

/** Trigger a download of `url` (archives, DCF, backups) without leaving the page. */
export function download(url: string): void {
  const link = h("a", { href: url, download: "" });
  document.body.append(link);
  link.click();
  link.remove();
}

/** Read a file chosen by the user (archive upload, EDS import). */
export function pickFile(accept: string): Promise<File | null> {
  return new Promise((resolve) => {
    const input = h("input", { type: "file", accept, style: { display: "none" } });
    input.addEventListener("change", () => {
      resolve(input.files?.[0] ?? null);
      input.remove();
    });
    document.body.append(input);
    input.click();
  });
}
