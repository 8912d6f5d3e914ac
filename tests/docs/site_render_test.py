#!/usr/bin/python3
"""Opens pages of the built documentation site (BUILD/site, from scripts/build_docs.py) in
headless Chromium and checks that they render: the page's title heading is in the DOM after
its scripts ran, the screenshot is not blank (most of it neither one colour nor white), and the
browser's console stays silent (a static page of the site logs nothing; any message, an
uncaught exception or a resource that failed to load among them, is a failure).

The site is served from 127.0.0.1 (a port of this machine: no network), as
`python3 -m http.server -d build/site` serves it to a reader; the search's index is fetched,
which a file:// URL does not allow.

Usage: site_render_test.py --site DIR [PAGE=HEADING ...]
Exit codes: 0 rendered; 1 a page failed; 77 Chromium is not installed or the site not built.
"""
import argparse
import functools
import http.server
import os
import re
import shutil
import subprocess
import sys
import tempfile
import threading

DEFAULT_PAGES = ["index.html=jelly", "getting-started.html=Getting started",
                 "reference/cli.html=Command line"]


def chromium():
    for name in ("chromium", "chromium-browser", "google-chrome"):
        path = shutil.which(name)
        if path:
            return path
    return None


def browse(browser, url, profile, extra):
    """(exit status, stdout, console lines) of one headless run."""
    command = [browser, "--headless", "--no-sandbox", "--disable-gpu", "--hide-scrollbars",
               "--no-first-run", "--disable-extensions", "--disable-background-networking",
               "--disable-component-update", "--disable-dev-shm-usage", "--window-size=1200,900",
               f"--user-data-dir={profile}", "--enable-logging=stderr", "--v=0"] + extra + [url]
    result = subprocess.run(command, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True,
                            timeout=120)
    console = [line for line in result.stderr.split("\n") if ":CONSOLE" in line]
    return result.returncode, result.stdout, console


def not_blank(png):
    """(ok, why) for a screenshot: several colours, and at least 2 % of pixels not the
    background's colour."""
    import numpy as np
    # ffmpeg (a dependency of jelly render) decodes the PNG into raw RGB bytes
    raw = subprocess.run(["ffmpeg", "-v", "error", "-i", png, "-f", "rawvideo", "-pix_fmt",
                          "rgb24", "-"], stdout=subprocess.PIPE, check=True).stdout
    pixels = np.frombuffer(raw, dtype=np.uint8).reshape(-1, 3)
    packed = (pixels[:, 0].astype(np.uint32) << 16) | (pixels[:, 1].astype(np.uint32) << 8) \
        | pixels[:, 2]
    colours, counts = np.unique(packed, return_counts=True)
    other = 1 - counts.max() / len(packed)
    why = f"{len(colours)} colours, {100 * other:.1f} % of pixels off background"
    return len(colours) >= 16 and other >= 0.02, why


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--site", required=True)
    parser.add_argument("pages", nargs="*", default=DEFAULT_PAGES)
    args = parser.parse_args()
    browser = chromium()
    if not browser:
        print("site_render_test: Chromium is not installed (Debian package chromium:"
              " scripts/install-deps.sh --docs): skipped")
        return 77
    if not os.path.exists(os.path.join(args.site, "index.html")):
        print(f"site_render_test: no site in {args.site} (make docs): skipped")
        return 77

    class Quiet(http.server.SimpleHTTPRequestHandler):
        def log_message(self, *args):
            pass

    handler = functools.partial(Quiet, directory=args.site)
    server = http.server.ThreadingHTTPServer(("127.0.0.1", 0), handler)
    threading.Thread(target=server.serve_forever, daemon=True).start()
    base = f"http://127.0.0.1:{server.server_address[1]}/"
    failures = []
    work = tempfile.mkdtemp(prefix="jelly-site-")
    try:
        for spec in args.pages:
            page, _, heading = spec.partition("=")
            url = base + page
            profile = os.path.join(work, "profile")
            status, dom, console = browse(browser, url, profile, ["--dump-dom"])
            shutil.rmtree(profile, ignore_errors=True)
            problems = []
            if status != 0:
                problems.append(f"chromium --dump-dom exited {status}")
            titles = [re.sub(r"<[^>]+>", "", t).strip()
                      for t in re.findall(r"<h1[^>]*>(.*?)</h1>", dom, re.S)]
            if not any(heading in t for t in titles):
                problems.append(f"no <h1> with '{heading}' (found {titles})")
            if "md-content" not in dom:
                problems.append("the theme's content area (md-content) is missing")
            png = os.path.join(work, page.replace("/", "_") + ".png")
            status, _, console2 = browse(browser, url, profile, [f"--screenshot={png}"])
            shutil.rmtree(profile, ignore_errors=True)
            if status != 0 or not os.path.exists(png):
                problems.append(f"chromium --screenshot exited {status}, no {png}")
                ok, why = False, "no screenshot"
            else:
                ok, why = not_blank(png)
                if not ok:
                    problems.append(f"blank screenshot: {why}")
            for line in console + console2:
                problems.append("console: " + line.split("] ", 1)[-1])
            print(f"{page}: {'ok' if not problems else 'FAILED'} (screenshot: {why})")
            for problem in problems:
                print(f"  {problem}")
            if problems:
                failures.append(page)
    finally:
        server.shutdown()
        shutil.rmtree(work, ignore_errors=True)
    if failures:
        print(f"site_render_test: {len(failures)} page(s) failed: {', '.join(failures)}")
        return 1
    return 0


if __name__ == "__main__":
    sys.exit(main())
