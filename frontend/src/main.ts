import "./style.css";
import { App } from "./app";

void new App(document.querySelector<HTMLElement>("#app")!).start();
