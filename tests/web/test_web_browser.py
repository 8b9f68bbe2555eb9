"""The page in Debian's Chromium, headless, through Selenium: an STL uploaded with the coarse recipe, the progress,
the heat map and the report's figures shown, the G-code downloaded by its link and compared with the planner's
own file in the job's folder; a sign made on the page; a refusal shown."""
from __future__ import annotations

import time

import pytest

from tmm_workbench.core.shared_data import benchmark_file

pytestmark = pytest.mark.xdist_group("web")
CHROMEDRIVER = "/usr/bin/chromedriver"
CHROMIUM = "/usr/bin/chromium"


@pytest.fixture
def browser(tmp_path):
    from selenium import webdriver
    from selenium.webdriver.chrome.service import Service

    downloads = tmp_path / "downloads"
    downloads.mkdir()
    opts = webdriver.ChromeOptions()
    opts.binary_location = CHROMIUM
    for arg in ("--headless=new", "--no-sandbox", "--disable-dev-shm-usage", "--disable-gpu",
                "--window-size=1200,1600"):
        opts.add_argument(arg)
    opts.add_experimental_option("prefs", {"download.default_directory": str(downloads),
                                           "download.prompt_for_download": False})
    driver = webdriver.Chrome(service=Service(CHROMEDRIVER), options=opts)
    driver.execute_cdp_cmd("Page.setDownloadBehavior", {"behavior": "allow", "downloadPath": str(downloads)})
    driver.downloads = downloads
    yield driver
    driver.quit()


def _wait(what, limit_s: float, message: str):
    end = time.monotonic() + limit_s
    while time.monotonic() < end:
        got = what()
        if got:
            return got
        time.sleep(0.3)
    raise AssertionError(message)


def _choose(driver, select_id: str, value: str) -> None:
    from selenium.webdriver.common.by import By
    from selenium.webdriver.support.ui import Select

    Select(driver.find_element(By.ID, select_id)).select_by_value(value)


def _plan_on_page(driver, server) -> tuple[str, list[str]]:
    """Submits the filled form and follows the page until the job ends: its id and the states the page showed."""
    from selenium.webdriver.common.by import By

    for field, value in (("material", "modelling_foam"), ("finish", "draft"), ("machine", "3-axis linuxcnc")):
        _choose(driver, field, value)
    driver.find_element(By.ID, "submit").click()
    shown: list[str] = []

    def ended():
        text = driver.find_element(By.ID, "status").text
        if text and (not shown or shown[-1] != text):
            shown.append(text)
        return driver.execute_script("return document.body.dataset.state || ''")

    _wait(ended, 120, f"the page shows no end: {shown}, error {driver.find_element(By.ID, 'error').text!r}")
    ended()   # the status the page shows at the end (it may change between the last read of the text and the state)
    return driver.execute_script("return document.body.dataset.job"), shown


def _open(driver, server) -> None:
    driver.get(server.url + "/")
    _wait(lambda: driver.execute_script("return document.body.dataset.ready"), 20, "the page did not load")


def test_upload_to_download_in_the_browser(server, browser):
    from selenium.webdriver.common.by import By

    _open(browser, server)
    browser.find_element(By.ID, "model").send_keys(str(benchmark_file("stl", "beet_mm.stl")))
    job_id, shown = _plan_on_page(browser, server)
    assert browser.execute_script("return document.body.dataset.state") == "verified", browser.page_source[-3000:]
    assert any("queued" in s or "planning" in s for s in shown) and "verified" in shown[-1], shown
    figures = browser.find_element(By.ID, "figures").text
    assert "cycle time" in figures and "deepest gouge" in figures and "verified yes" in figures, figures
    for img in ("heatmap", "toolpath"):
        assert browser.execute_script(f"const i = document.getElementById('{img}'); return i.complete && i.naturalWidth") > 100
    links = {a.text: a for a in browser.find_elements(By.CSS_SELECTOR, "a.download")}
    assert {"part.ngc", "part.FCStd", "part_sim.png", "toolpath.png", "report.json"} <= set(links), links
    links["part.ngc"].click()
    got = _wait(lambda: [p for p in browser.downloads.iterdir() if p.name == "part.ngc"], 30, "no download")[0]
    planner_own = next((server.jobs / job_id / "out").glob("job-*")) / "part.ngc"
    _wait(lambda: got.stat().st_size == planner_own.stat().st_size, 10, "the download did not complete")
    assert got.read_bytes() == planner_own.read_bytes() and got.read_text().count("\nG1") > 100


def test_a_sign_made_on_the_page(server, browser):
    """The sign's fields reach the server as a sign job whose progress the page follows (its planning to G-code is
    test_web_api's, through the API: not twice here)."""
    from selenium.webdriver.common.by import By

    _open(browser, server)
    browser.find_element(By.ID, "src-sign").click()
    text = browser.find_element(By.ID, "text")
    text.clear()
    text.send_keys("OK")
    _choose(browser, "shape", "ellipse")
    _choose(browser, "background", "waves")
    for field, value in (("material", "mdf"), ("finish", "draft"), ("machine", "3-axis grbl")):
        _choose(browser, field, value)
    browser.find_element(By.ID, "submit").click()
    job_id = _wait(lambda: browser.execute_script("return document.body.dataset.job"), 20, "no job accepted")
    _wait(lambda: job_id in browser.find_element(By.ID, "status").text, 10, "no progress shown")
    st = server.status(job_id)
    assert st["source"] == "sign 'OK'" and st["recipe"] == {"material": "mdf", "finish": "draft",
                                                           "machine": "3-axis grbl"}, st
    spec = (server.jobs / job_id / "job.yaml").read_text()
    assert "post: grbl" in spec and "material: mdf" in spec
    assert b"OK" in (server.jobs / job_id / "model.stl").read_bytes()[:80]   # the sign's mesh, named after it


def test_a_refusal_is_shown_on_the_page(server, browser, tmp_path):
    from selenium.webdriver.common.by import By

    bad = tmp_path / "notes.stl"
    bad.write_text("these are my notes, not a mesh\n")
    _open(browser, server)
    browser.find_element(By.ID, "model").send_keys(str(bad))
    browser.find_element(By.ID, "submit").click()
    msg = _wait(lambda: browser.find_element(By.ID, "error").text, 20, "no refusal shown")
    assert "refused (400)" in msg and "not a readable STL" in msg, msg
