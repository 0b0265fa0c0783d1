"""The dashboard in headless Chromium against the real server (two tokens): the jobs page signs
in with a token, shows a job submitted after it opened reach `succeeded` without a reload,
filters, cancels and retries; the job page's viewer draws both meshes; the other token's pages
show neither the job nor its viewer. Screenshots are written to ui-screenshots/ in the
cargo target directory ($CARGO_TARGET_DIR, else target/) or $SURFMAP_UI_SCREENSHOTS."""

from __future__ import annotations

import os
import pathlib

import pytest

from harness import ANCHORS, deformed, icosphere

from surfmap import Client

ROOT = pathlib.Path(__file__).resolve().parents[2]
TARGET = pathlib.Path(os.environ.get("CARGO_TARGET_DIR", ROOT / "target"))
SHOTS = pathlib.Path(os.environ.get("SURFMAP_UI_SCREENSHOTS", TARGET / "ui-screenshots"))
TIMEOUT_MS = 180_000


def watch_errors(page):
    errors = []
    page.on("console", lambda m: errors.append(f"console.{m.type}: {m.text}") if m.type == "error" else None)
    page.on("pageerror", lambda e: errors.append(f"pageerror: {e}"))
    return errors


def row(page, job_id):
    return page.locator(f'tr.job[data-id="{job_id}"]')


@pytest.fixture(scope="module")
def meshes():
    v, f = icosphere(4)
    return (v, f), (deformed(v), f)


def test_dashboard(server, browser, meshes):
    SHOTS.mkdir(parents=True, exist_ok=True)
    alpha = Client(server.url, token="alpha-token")
    ctx = browser.new_context(viewport={"width": 1280, "height": 900})
    page = ctx.new_page()
    errors = watch_errors(page)

    # The jobs page asks for a token and keeps it for the tab.
    page.goto(f"{server.url}/ui/")
    page.fill("#login input[name=token]", "alpha-token")
    page.click("#login button")
    page.wait_for_selector("#empty:not([hidden])")
    page.evaluate("window.__loaded_once = true")
    assert page.evaluate("sessionStorage.getItem('surfmap-token')") == "alpha-token"

    # Jobs submitted now appear and change on the open page: a long job holds the only worker,
    # a small one waits behind it (queued); the long one is cancelled from its row, then the
    # small one runs and succeeds, all followed over the events stream.
    page.evaluate("""() => { window.__states = []; new MutationObserver(() => {
        for (const r of document.querySelectorAll('tr.job')) window.__states.push(r.dataset.id + ':' + r.dataset.state); })
        .observe(document.querySelector('#jobs tbody'), {childList: true, subtree: true}); }""")
    lv, lf = icosphere(5)
    long = alpha.submit((lv, lf), (deformed(lv), lf), {"method": "voronoi", "anchors": ANCHORS,
                                                         "options": {"smoothing": {"iterations": 10000, "tolerance": 0.0}}})
    for j in alpha.events(long.id):
        if j.state == "running":
            break
    job = alpha.map(meshes[0], meshes[1], {"method": "voronoi", "anchors": ANCHORS})
    page.wait_for_selector(f'tr.job[data-id="{job.id}"][data-state="queued"]', timeout=30_000)
    page.wait_for_selector(f'tr.job[data-id="{long.id}"][data-state="running"]', timeout=30_000)
    page.screenshot(path=str(SHOTS / "jobs-running.png"), full_page=True)
    row(page, long.id).locator("button.cancel").click()
    page.wait_for_selector(f'tr.job[data-id="{long.id}"][data-state="cancelled"]', timeout=60_000)
    page.wait_for_selector(f'tr.job[data-id="{job.id}"][data-state="succeeded"]', timeout=TIMEOUT_MS)
    assert page.evaluate("window.__loaded_once") is True, "the page was reloaded"
    states = [s.split(":", 1)[1] for s in page.evaluate("window.__states") if s.startswith(job.id)]
    assert states[0] == "queued" and states[-1] == "succeeded", states
    assert row(page, job.id).locator(".stage").inner_text() != ""
    assert "100%" in row(page, job.id).locator(".progress").inner_text()
    page.screenshot(path=str(SHOTS / "jobs.png"), full_page=True)

    # Filters: by state and by method.
    page.select_option("#filters select[name=state]", "failed")
    page.wait_for_selector("#empty:not([hidden])")
    assert row(page, job.id).count() == 0
    page.select_option("#filters select[name=state]", "succeeded")
    page.select_option("#filters select[name=method]", "voronoi")
    row(page, job.id).wait_for()
    assert row(page, long.id).count() == 0
    assert "state=succeeded" in page.url and "method=voronoi" in page.url
    page.select_option("#filters select[name=method]", "greedy")
    page.wait_for_selector("#empty:not([hidden])")
    page.select_option("#filters select[name=state]", "")
    page.select_option("#filters select[name=method]", "")

    # Retry the cancelled job from its row: a new job with the same meshes and spec.
    row(page, long.id).locator("button.retry").click(timeout=30_000)
    page.wait_for_function(f"""() => [...document.querySelectorAll('tr.job')].some(
        r => r.dataset.id !== '{long.id}' && r.dataset.id !== '{job.id}')""", timeout=30_000)
    retried = [j for j in alpha.jobs() if j.id not in (job.id, long.id)]
    assert len(retried) == 1 and retried[0].spec == alpha.job(long.id).spec
    assert retried[0].meshes == long.meshes
    alpha.cancel(retried[0].id)

    # The job page: spec, timings, metrics, artifacts, and the viewer drawing both meshes.
    row(page, job.id).locator("a").first.click()
    page.wait_for_url(f"**/ui/jobs/{job.id}")
    page.wait_for_function("!!window.surfmapViewer", timeout=60_000)
    assert page.locator("#state").inner_text() == "succeeded"
    assert '"method": "voronoi"' in page.locator("#spec").inner_text()
    assert page.locator("table.timings tr").count() > 2
    assert page.locator("a.artifact", has_text="morph.glb").count() == 1
    assert "flipped_faces" in page.locator("table.metrics").inner_text()
    assert "null" not in page.locator("#details").inner_text().split("metrics.json")[-1]
    cov = page.evaluate("window.surfmapViewer.coverage()")
    area = cov["width"] * cov["height"] / 2
    assert cov["left"] > 0.02 * area and cov["right"] > 0.02 * area, cov
    page.eval_on_selector("#morph", "e => { e.value = '0.6'; e.dispatchEvent(new Event('input')); }")
    page.screenshot(path=str(SHOTS / "job.png"), full_page=True)
    page.select_option("#colouring", "checker")
    page.locator("#viewer canvas").screenshot(path=str(SHOTS / "viewer-checker.png"))
    page.select_option("#colouring", "distortion")
    cov2 = page.evaluate("window.surfmapViewer.coverage()")
    assert cov2["left"] > 0.02 * area and cov2["right"] > 0.02 * area, cov2
    page.locator("#viewer canvas").screenshot(path=str(SHOTS / "viewer-distortion.png"))
    assert errors == [], errors

    # A quad job's page: the two remeshes side by side, and the geometry images.
    quad = alpha.map(meshes[0], meshes[1], {"method": "quad", "anchors": [[0, 0], [3, 3], [4, 4], [7, 7]],
                                             "options": {"level": 3}}, wait=True, timeout=300)
    page.goto(f"{server.url}/ui/jobs/{quad.id}")
    page.wait_for_function("!!window.surfmapViewer", timeout=60_000)
    cov = page.evaluate("window.surfmapViewer.coverage()")
    assert cov["left"] > 0.02 * area and cov["right"] > 0.02 * area, cov
    assert page.locator("#viewer .tag.right").inner_text() == "remesh of mesh 1"
    n_png = sum(a.name.endswith(".png") for a in quad.artifacts)
    assert n_png >= 4
    page.wait_for_function(f"""() => [...document.querySelectorAll('#geometry-images img')]
        .filter(i => i.complete && i.naturalWidth > 0).length === {n_png}""", timeout=30_000)
    page.screenshot(path=str(SHOTS / "job-quad.png"), full_page=True)
    assert errors == [], errors

    # The cancelled job's page: its state, its error code if it has one, a retry button, no viewer.
    page.goto(f"{server.url}/ui/jobs/{long.id}")
    page.wait_for_selector("#state")
    assert page.locator("#state").inner_text() == "cancelled"
    code = alpha.job(long.id).error
    if code:
        assert page.locator("#error-code").inner_text() == code.code
    assert page.locator("button.retry").count() == 1 and page.locator("#viewer-section").is_hidden()
    assert errors == [], errors

    # Another token (sent by a front proxy on every request: honoured, no prompt) sees no job.
    other = browser.new_context(viewport={"width": 1280, "height": 700},
                                extra_http_headers={"Authorization": "Bearer beta-token"})
    page2 = other.new_page()
    errors2 = watch_errors(page2)
    page2.goto(f"{server.url}/ui/")
    page2.wait_for_selector("#empty:not([hidden])")
    assert page2.locator("#login").count() == 0
    assert page2.locator("tr.job").count() == 0 and job.id[-12:] not in page2.content()
    page2.screenshot(path=str(SHOTS / "jobs-other-token.png"), full_page=True)
    page2.goto(f"{server.url}/ui/jobs/{job.id}")
    page2.wait_for_selector("#status.error")
    assert "No job" in page2.locator("#status").inner_text()
    assert page2.locator("#viewer-section").is_hidden()
    assert [e for e in errors2 if "404" not in e] == [], errors2
    # A page request with a wrong token is refused outright.
    bad = browser.new_context(extra_http_headers={"Authorization": "Bearer wrong"})
    resp = bad.new_page().goto(f"{server.url}/ui/")
    assert resp.status == 401
    for c in (ctx, other, bad):
        c.close()
    alpha.close()
