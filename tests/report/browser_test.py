#!/usr/bin/env python3
"""The page of `plumb report` in a browser (issue 13 point 10), run by CTest.

1. scripts/check-page fails when it should: pages with a broken image, a request to another
   file beside the page, a request to the network, a console error, an uncaught exception, a
   figure of zero size, too few figures; and passes a page that is fine.
2. A real report stands alone: `plumb report` on the bundled session data/mikoff/imu0.log;
   its index.html copied alone into an empty folder loads in headless Chromium with no console
   error and no request, its figures have a non-zero size; the screenshot is kept in OUT.

  browser_test.py --plumb PLUMB --checker scripts/check-page --session FILE --out DIR

Exit 0 when every check passes, 1 otherwise, 77 (CTest: skipped) when Chromium is absent.
"""
import argparse
import shutil
import subprocess
import sys
from pathlib import Path

SKIP = 77
FIGURE = ('<figure id="figure-a"><svg width="200" height="100" viewBox="0 0 200 100">'
          '<rect width="200" height="100" fill="#dce6f2"/></svg></figure>')


def page(body, head=""):
    return ("<!DOCTYPE html>\n<html lang=\"en\"><head><meta charset=\"utf-8\"><title>t</title>"
            + head + "</head><body>" + body + "</body></html>\n")


# name -> (page, files beside it, --min-figures, the failure expected or None for a pass)
CASES = {
    "fine": (page(FIGURE), {}, 1, None),
    "broken_image": (page('<figure><img src="missing.png" alt="x"></figure>'), {}, 0,
                     "broken image: missing.png"),
    "file_beside": (page(FIGURE, '<link rel="stylesheet" href="style.css">'),
                    {"style.css": "body { color: #222; }\n"}, 1,
                    "request other than the page: file://"),
    "network": (page(FIGURE, '<link rel="stylesheet" href="https://plumb.invalid/style.css">'),
                {}, 1, "request other than the page: https://plumb.invalid/style.css"),
    "console_error": (page(FIGURE + "<script>console.error('figure missing')</script>"), {}, 1,
                      "console error: figure missing"),
    "exception": (page(FIGURE + "<script>undefined_function()</script>"), {}, 1,
                  "uncaught exception"),
    "zero_size": (page('<figure id="figure-z"><svg width="0" height="0"></svg></figure>'), {}, 1,
                  "figure-z has a zero size"),
    "too_few_figures": (page("<p>no figure</p>"), {}, 1, "0 figures, fewer than the 1 expected"),
}


def run(args, **kw):
    return subprocess.run(args, stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True, **kw)


STUDY = ('{"name": "one pose", "seed": 5, "runs": 2, "design": "one_at_a_time",'
         ' "base": {"schedule": "paper_static", "still_s": 10, "rate_hz": 100, "sensor": "typical",'
         ' "lat_deg": 6.67, "lon_deg": -1.57, "height_m": 250}, "fit": {"method": "generalized"},'
         ' "factors": [{"name": "level_error_deg", "levels": [0, 1]},'
         ' {"name": "fit_gravity_m_s2", "levels": [0, 9.80665]}]}')


def study_page(args, verdict):
    """Part 3 of the module comment."""
    study = args.out / "study.json"
    study.write_text(STUDY)
    folder = args.out / "study"
    r = run([args.plumb, "sweep", str(study), "--out", str(folder), "--jobs", "1"])
    verdict("plumb sweep writes the study's page", r.returncode == 0, r.stdout)
    if r.returncode != 0:
        return
    alone = args.out / "study_alone"
    alone.mkdir()
    shutil.copy(folder / "index.html", alone / "index.html")
    html = (alone / "index.html").read_text()
    for factor in ("level_error_deg", "fit_gravity_m_s2"):
        for n in range(6):  # the rows of the raw parameters, undetermined, are not drawn
            verdict("an error figure of combination %d against %s" % (n, factor),
                    ('<figure id="fig-error_%s_%d">' % (factor, 21 + n)) in html, "")
    verdict("the y axes have units", html.count("error, estimate - truth (m/s^2)") == 6 and
            html.count("error, estimate - truth (rad/s)") == 6, "")
    verdict("the gravity factor is drawn by level", "fit_gravity_m_s2 (m/s^2), by level" in html
            and "WGS84<" in html, "")
    r = run([sys.executable, args.checker, str(alone / "index.html"), "--min-figures", "14",
             "--screenshot", str(args.out / "study.png")])
    verdict("the study's page alone: no console error, no request, 14 figures of non-zero size",
            r.returncode == 0, r.stdout)


def main():
    parser = argparse.ArgumentParser()
    parser.add_argument("--plumb", required=True)
    parser.add_argument("--checker", required=True)
    parser.add_argument("--session", required=True)
    parser.add_argument("--out", required=True, type=Path)
    args = parser.parse_args()
    if shutil.which("chromium") is None:
        print("SKIP: chromium is not installed (Debian: apt-get install chromium; scripts/setup "
              "installs it)")
        return SKIP
    if args.out.exists():
        shutil.rmtree(args.out)
    args.out.mkdir(parents=True)
    passed, failed = 0, 0

    def verdict(name, ok, output):
        nonlocal passed, failed
        print(("ok    " if ok else "FAIL  ") + name)
        if not ok:
            print("      " + output.replace("\n", "\n      "))
        passed += ok
        failed += not ok

    for name, (html, files, figures, expected) in CASES.items():
        folder = args.out / "pages" / name
        folder.mkdir(parents=True)
        (folder / "index.html").write_text(html)
        for file, content in files.items():
            (folder / file).write_text(content)
        r = run([sys.executable, args.checker, str(folder / "index.html"),
                 "--min-figures", str(figures)])
        if expected is None:
            verdict("checker passes the page '%s'" % name, r.returncode == 0, r.stdout)
        else:
            verdict("checker fails the page '%s' (%s)" % (name, expected),
                    r.returncode == 1 and ("FAIL: " + expected) in r.stdout, r.stdout)

    # A real report, its page alone in an empty folder.
    report = args.out / "report"
    r = run([args.plumb, "report", args.session, "--columns", "ax,ay,az,gx,gy,gz", "--rate", "100",
             "--out", str(report)])
    verdict("plumb report writes the page", r.returncode == 0, r.stdout)
    if r.returncode == 0:
        alone = args.out / "alone"
        alone.mkdir()
        shutil.copy(report / "index.html", alone / "index.html")
        shot = args.out / "report.png"
        r = run([sys.executable, args.checker, str(alone / "index.html"), "--min-figures", "4",
                 "--screenshot", str(shot)])
        print("      " + r.stdout.strip().replace("\n", "\n      "))
        verdict("the report's page alone: no console error, no request, 4 figures of non-zero "
                "size", r.returncode == 0, r.stdout)
        verdict("the screenshot is a PNG (%s)" % shot,
                shot.is_file() and shot.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n", "")
    study_page(args, verdict)
    print("%d passed, %d failed" % (passed, failed))
    return 0 if failed == 0 else 1


if __name__ == "__main__":
    sys.exit(main())
