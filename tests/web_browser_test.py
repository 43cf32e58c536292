#!/usr/bin/python3
"""The query page in a real browser: headless Chromium, driven over the
DevTools protocol, against `meshseek web` on an embedded stack holding the
synthetic benchmark.

The gateway wants a bearer token: the page is refused (401), asks for it,
and sends it from then on. It uploads a model file through the page's file
input, waits for the ranking and asserts on the DOM: the first result is the
uploaded model itself (distance 0: the same file gives the same features),
every thumbnail loaded, most of the top results share its class; then it
clicks a result (a query by model id), uploads a picture (the model's own
thumbnail, a shaded view on a plain background: a query by its silhouette)
and a broken file (a clear error naming it). With --screenshot FILE it saves
the ranked page of the mesh, with --picture_screenshot FILE the picture's.

  tests/web_browser_test.py --build build [--screenshot docs/images/web-query.png]
      [--picture_screenshot docs/images/web-picture-query.png]

Exit 0: passed; 77: Chromium or python3-websocket missing (skipped); other:
failed, with the reason on stderr.
"""
import argparse
import base64
import csv
import json
import os
import shutil
import signal
import socket
import subprocess
import sys
import tempfile
import time
import urllib.request

try:
    import websocket  # python3-websocket
except ImportError:
    websocket = None

SKIP = 77


def free_port():
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        return s.getsockname()[1]


def wait_for(what, predicate, timeout=60.0, every=0.2):
    deadline = time.time() + timeout
    while time.time() < deadline:
        value = predicate()
        if value:
            return value
        time.sleep(every)
    raise AssertionError(f"timed out after {timeout:.0f} s waiting for {what}")


class DevTools:
    """The few DevTools protocol calls the test needs, one page."""

    def __init__(self, port):
        def page_socket():
            try:
                with urllib.request.urlopen(f"http://127.0.0.1:{port}/json/list", timeout=2) as r:
                    pages = [t for t in json.load(r) if t["type"] == "page"]
                return pages[0]["webSocketDebuggerUrl"] if pages else None
            except OSError:
                return None

        url = wait_for("Chromium's DevTools endpoint", page_socket, timeout=30)
        self.ws = websocket.create_connection(url, timeout=60, suppress_origin=True)
        self.next_id = 0

    def call(self, method, **params):
        self.next_id += 1
        self.ws.send(json.dumps({"id": self.next_id, "method": method, "params": params}))
        while True:
            message = json.loads(self.ws.recv())
            if message.get("id") == self.next_id:
                if "error" in message:
                    raise AssertionError(f"{method}: {message['error']}")
                return message.get("result", {})

    def js(self, expression):
        result = self.call("Runtime.evaluate", expression=expression, returnByValue=True,
                           awaitPromise=True)
        if "exceptionDetails" in result:
            raise AssertionError(f"{expression}: {result['exceptionDetails']}")
        return result["result"].get("value")

    def upload(self, path):
        root = self.call("DOM.getDocument")["root"]["nodeId"]
        node = self.call("DOM.querySelector", nodeId=root, selector="#mesh-file")["nodeId"]
        self.js("document.body.dataset.state = 'waiting'")
        self.call("DOM.setFileInputFiles", files=[path], nodeId=node)

    def wait_state(self):
        return wait_for("the page to show results or an error",
                        lambda: self.js("document.body.dataset.state") in ("results", "error")
                        and self.js("document.body.dataset.state"))


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--build", default="build", help="meshseek's build folder")
    parser.add_argument("--screenshot", help="save the mesh query's ranked page here (PNG)")
    parser.add_argument("--picture_screenshot",
                        help="save the picture query's ranked page here (PNG)")
    parser.add_argument("--keep", action="store_true", help="keep the temporary folder")
    args = parser.parse_args()
    chromium = shutil.which("chromium") or shutil.which("chromium-browser")
    if chromium is None or websocket is None:
        print("web_browser_test: skipped (needs Debian chromium and python3-websocket)")
        return SKIP
    meshseek = os.path.abspath(os.path.join(args.build, "cli", "meshseek"))
    work = tempfile.mkdtemp(prefix="meshseek-web-")
    processes = []
    try:
        synth = os.path.join(work, "synth")
        data = os.path.join(work, "data")
        subprocess.run([meshseek, "synth", "--out", synth, "--models_per_class", "4"], check=True,
                       stdout=subprocess.DEVNULL)
        # dld+lfd: LFD's views answer pictures.
        subprocess.run([meshseek, "eval", "--manifest", os.path.join(synth, "manifest.csv"),
                        "--method", "dld+lfd", "--collection", "synthetic", "--data_dir", data,
                        "--out", os.path.join(work, "eval")], check=True, stdout=subprocess.DEVNULL)
        with open(os.path.join(synth, "manifest.csv")) as f:
            models = list(csv.DictReader(f))
        query = next(m for m in models if m["class"] == "spider")
        query_path = os.path.join(synth, query["path"])

        web_port = free_port()
        token = "browser-test-token"
        token_file = os.path.join(work, "token")
        with open(token_file, "w") as f:
            f.write(token + "\n")
        web = subprocess.Popen([meshseek, "web", "--data_dir", data, "--port", str(web_port),
                                "--web_token_file", token_file],
                               stdout=subprocess.PIPE, text=True)
        processes.append(web)
        line = web.stdout.readline()
        if "meshseek web" not in line:
            raise AssertionError(f"meshseek web did not start: {line!r}")

        devtools_port = free_port()
        browser = subprocess.Popen(
            [chromium, "--headless=new", "--no-sandbox", "--disable-gpu", "--no-first-run",
             "--hide-scrollbars", f"--remote-debugging-port={devtools_port}",
             f"--user-data-dir={os.path.join(work, 'chromium')}", "--window-size=1280,1000",
             "about:blank"], stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
        processes.append(browser)
        page = DevTools(devtools_port)
        page.call("Page.enable")
        page.call("Page.navigate", url=f"http://127.0.0.1:{web_port}/?collection=synthetic")
        # Refused without the token: the page asks for it.
        wait_for("the token form", lambda: page.js("document.querySelector('#token-form')?.hidden === false"))
        page.js(f"document.querySelector('#token').value = {json.dumps(token)}; "
                "document.querySelector('#token-form').requestSubmit()")
        wait_for("the collection list", lambda: page.js(
            "document.querySelector('#collection')?.value") == "synthetic")

        # Upload: the model itself comes first, and its class dominates.
        page.upload(query_path)
        state = page.wait_state()
        error = page.js("document.querySelector('#error').textContent")
        assert state == "results", f"the page shows an error: {error}"
        ids = page.js("[...document.querySelectorAll('.result')].map(r => r.dataset.modelId)")
        labels = page.js("[...document.querySelectorAll('.result')].map(r => r.dataset.label)")
        assert ids and ids[0] == query["id"], f"first result {ids[:3]}, expected {query['id']}"
        same = sum(1 for label in labels[:3] if label == query["class"])
        assert same >= 2, f"top 3 labels {labels[:3]}, expected mostly {query['class']}"
        wait_for("every thumbnail to load", lambda: page.js(
            "[...document.querySelectorAll('.result img')].every(i => i.complete && "
            "i.naturalWidth === 128)"), timeout=30)
        assert page.js("document.querySelector('#query-thumbnail').naturalWidth") == 128
        print(f"web_browser_test: upload of {os.path.basename(query_path)} ({query['class']}): "
              f"first result {ids[0]}, top labels {labels[:5]}")
        if args.screenshot:
            shot = page.call("Page.captureScreenshot", format="png")
            os.makedirs(os.path.dirname(os.path.abspath(args.screenshot)), exist_ok=True)
            with open(args.screenshot, "wb") as f:
                f.write(base64.b64decode(shot["data"]))
            print(f"web_browser_test: wrote {args.screenshot}")

        # Click the second result: a query by model id puts it first.
        second = ids[1]
        page.js("document.querySelectorAll('.result')[1].click()")
        wait_for("the clicked model's query", lambda: page.js(
            "document.body.dataset.state === 'results' && "
            "document.querySelector('#query-name').textContent") == second)
        first = page.js("document.querySelector('.result').dataset.modelId")
        assert first == second, f"clicked {second}, first result {first}"

        # A picture: the model's own thumbnail, fetched with the token.
        thumbnail = urllib.request.Request(
            f"http://127.0.0.1:{web_port}/api/thumbnail?collection=synthetic&model_id={query['id']}",
            headers={"Authorization": f"Bearer {token}"})
        picture = os.path.join(work, "picture.png")
        with urllib.request.urlopen(thumbnail, timeout=30) as r, open(picture, "wb") as f:
            f.write(r.read())
        page.upload(picture)
        state = page.wait_state()
        error = page.js("document.querySelector('#error').textContent")
        assert state == "results", f"the picture's query shows an error: {error}"
        labels = page.js("[...document.querySelectorAll('.result')].map(r => r.dataset.label)")
        assert labels and labels[0] == query["class"], \
            f"picture of a {query['class']}: top labels {labels[:5]}"
        assert "silhouette" in page.js("document.querySelector('#query-status').textContent")
        wait_for("the picture and every thumbnail to load", lambda: page.js(
            "[...document.querySelectorAll('.result img'), document.querySelector('#query-thumbnail')]"
            ".every(i => i.complete && i.naturalWidth > 0)"), timeout=30)
        print(f"web_browser_test: picture of {query['id']} ({query['class']}): "
              f"top labels {labels[:5]}")
        if args.picture_screenshot:
            shot = page.call("Page.captureScreenshot", format="png")
            with open(args.picture_screenshot, "wb") as f:
                f.write(base64.b64decode(shot["data"]))
            print(f"web_browser_test: wrote {args.picture_screenshot}")

        # A broken file: a clear error naming it, no results replaced.
        broken = os.path.join(work, "broken.off")
        with open(broken, "w") as f:
            f.write("OFF\n4 2 0\n0 0 0\n1 0 0\n")
        page.upload(broken)
        assert page.wait_state() == "error"
        error = page.js("document.querySelector('#error').textContent")
        assert "broken.off" in error, f"error without the file's name: {error!r}"
        print(f"web_browser_test: broken file -> {error!r}")
        print("web_browser_test: passed")
        return 0
    except (AssertionError, subprocess.CalledProcessError) as e:
        print(f"web_browser_test: FAILED: {e}", file=sys.stderr)
        return 1
    finally:
        for p in reversed(processes):
            p.send_signal(signal.SIGTERM)
            try:
                p.wait(timeout=20)
            except subprocess.TimeoutExpired:
                p.kill()
        if not args.keep:
            shutil.rmtree(work, ignore_errors=True)


if __name__ == "__main__":
    sys.exit(main())
