# SPDX-License-Identifier: Apache-2.0
"""A headless chromium on a page, for the dashboard's browser tests; nothing of it left behind."""

from collections.abc import Iterator
from contextlib import contextmanager
import os
from pathlib import Path
import shutil

WINDOW = '1400,1300'


@contextmanager
def headless_chromium(url: str, directory: Path) -> Iterator[object]:
    """
    Yield a selenium driver of a headless chromium on ``url``; quit both at the end.

    Chromium keeps its profile and its singleton socket's folder (``org.chromium.Chromium.*``,
    made in the temporary directory) under ``directory``, the test's own, so a run leaves
    nothing in /tmp.
    """
    from selenium import webdriver
    from selenium.webdriver.chrome.service import Service

    chromium, chromedriver = shutil.which('chromium'), shutil.which('chromedriver')
    assert chromium and chromedriver, 'apt-get install chromium chromium-driver'
    options = webdriver.ChromeOptions()
    options.binary_location = chromium
    for argument in ('--headless=new', '--no-sandbox', '--disable-gpu',
                     '--disable-dev-shm-usage', f'--window-size={WINDOW}',
                     f'--user-data-dir={directory / "profile"}'):
        options.add_argument(argument)
    service = Service(chromedriver, env={**os.environ, 'TMPDIR': str(directory)})
    driver = webdriver.Chrome(options=options, service=service)
    try:
        driver.get(url)
        yield driver
    finally:
        driver.quit()
