/** Route → page module. */

import type { Page, PageContext } from "../app";
import { h } from "../lib/dom";
import { auditPage } from "./audit";
import { axisPage } from "./axis";
import { busPage } from "./bus";
import { comparePage } from "./compare";
import { dictionariesPage, dictionaryPage } from "./dictionaries";
import { homePage } from "./home";
import { loginPage, setupPage } from "./login";
import { motorsPage } from "./motors";
import { projectPage } from "./project";
import { terminalPage } from "./terminal";

export async function mountPage(context: PageContext): Promise<Page> {
  const route = context.location.route;
  switch (route.page) {
    case "home":
      return homePage(context);
    case "project":
      return projectPage(context, route.project);
    case "compare":
      return comparePage(context, route.project);
    case "axis":
      return axisPage(context, route.project, route.axis, route.view);
    case "bus":
      return busPage(context);
    case "terminal":
      return terminalPage(context);
    case "dictionaries":
      return dictionariesPage(context);
    case "dictionary":
      return dictionaryPage(context, route.device);
    case "motors":
      return motorsPage(context);
    case "audit":
      return auditPage(context);
    case "login":
      return loginPage(context);
    case "setup":
      return setupPage(context);
    case "not-found":
      return {
        title: "Not found",
        element: h("div", { class: "page" }, h("div", { class: "message error", "data-testid": "page-error" },
          `There is no page at ${route.path}.`), h("a", { href: "/" }, "Go to the projects")),
      };
  }
}
