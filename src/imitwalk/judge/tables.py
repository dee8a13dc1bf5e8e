"""The report's tables, as HTML: protocol judgements and push recovery (pure Python)."""

from __future__ import annotations

import html

from imitwalk.judge.records import ControllerVerdict, ProtocolVerdict, PushVerdict

__all__ = ["protocol_table", "push_table"]


def _pct(lo: float, hi: float) -> str:
    return f"{100 * lo:.0f}–{100 * hi:.0f} %"


def _num(x: float | None, fmt: str) -> str:
    return "–" if x is None else format(x, fmt)


def protocol_table(result: ProtocolVerdict) -> str:
    """One protocol's judgement (:func:`imitwalk.judge.verdict.judge_protocol`): a row per
    controller, and the falls by the factor each robot drew furthest from nominal."""
    p, st, sides, comp = result.protocol, result.settings, result.controllers, result.comparison
    factors = sorted({f for s in sides.values() for f in s.falls_by_furthest_factor})
    head = (
        "<tr><th>controller</th><th>survived</th><th>95 % CI</th><th>distance [m]</th>"
        "<th>speed [m/s]</th><th>mean |yaw| [°]</th><th>McNemar p vs open loop</th>"
        + "".join(f"<th>falls: {html.escape(f)}</th>" for f in factors)
        + "</tr>"
    )
    rows = []
    for name, s in sides.items():
        pval = comp.get(name, {}).get("mcnemar_p")
        cells = [
            html.escape(name),
            f"{s.survived}/{s.robots}",
            _pct(*s.survival_ci95),
            _num(s.distance_m, ".2f"),
            _num(s.speed_mps, ".3f"),
            _num(s.abs_yaw_deg, ".1f"),
            "–" if pval is None else f"{pval:.3g}",
            *(str(s.falls_by_furthest_factor.get(f, 0)) for f in factors),
        ]
        rows.append("<tr>" + "".join(f"<td>{c}</td>" for c in cells) + "</tr>")
    caption = (
        f"<p>Protocol <b>{html.escape(p.name)}</b> v{p.version}: "
        f"{st.seeds} robots × {st.seconds} s on {html.escape(st.engine)}"
        f", scale {st.scale}. A fall is counted under the factor its robot drew "
        "furthest from nominal.</p>"
    )
    return caption + "<table>" + head + "".join(rows) + "</table>" + _explained(sides)


def _explained(sides: dict[str, ControllerVerdict]) -> str:
    """The falls explained (``evaluate --explain-falls``), one line per controller."""
    lines = [
        f"<li>{html.escape(name)}: {html.escape(line)}</li>"
        for name, s in sides.items()
        if (line := s.explained()) is not None
    ]
    if not lines:
        return ""
    head = "<p>Falls saved by setting one factor alone back to nominal:</p>"
    return head + "<ul>" + "".join(lines) + "</ul>"


def push_table(result: PushVerdict) -> str:
    """Push recovery (:func:`imitwalk.judge.pushes.push_recovery`): the largest kick survived
    [m/s], a row per controller and direction, a column per phase of the gait cycle."""
    st = result.settings
    n = st.phases
    head = "<tr><th>controller</th><th>direction</th>" + "".join(
        f"<th>phase {k}/{n}</th>" for k in range(n)
    )
    rows = []
    for name, side in result.controllers.items():
        for d, speeds in side.table.items():
            cells = "".join(f"<td>{v:.2f}</td>" for v in speeds)
            rows.append(f"<tr><td>{html.escape(name)}</td><td>{d}</td>{cells}</tr>")
    note = (
        f"<p>Nominal robot at scale {st.scale}, one kick two cycles after the start-up; "
        f"the robot must stay up {st.after_s} s after it. Bisection to "
        f"{st.resolution_mps:.3f} m/s; {st.top_mps:.2f} means it "
        "survived the largest kick tried.</p>"
    )
    return note + "<table>" + head + "</tr>" + "".join(rows) + "</table>"
