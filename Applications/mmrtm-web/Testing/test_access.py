"""mmrtm-web lets in only the holder of its access key, over TLS when asked,
and writes no patient data to its log.

Run by ctest (vtk96-web-access) with the .venv-vtk96 interpreter (the wheel
with trame-slicer, aiohttp, selenium), MMRTM_SHARED_DATA_DIR set, Debian's
chromium and chromium-driver, and the openssl command.

What each part can catch:
- AccessRulesTest (no server): a cookie that outlives its expiry, a cookie
  of another key taken, a key file or certificate problem not named, an
  unsafe start (beyond loopback without TLS, or without a key) allowed.
- KeyTest (a server with its own key, a DICOM study whose patient name and
  ID are planted): any route (the page, its scripts, the WebSocket that
  carries the studies' listing, uploads and the PNG) answering without the
  key, with a wrong key, with an expired cookie or another key's cookie; a
  refusal that names a file of the data root; the key left in the address
  bar or a cookie readable by scripts or sent cross-site; the printed
  address not opening the study in Chromium, or a reload without the key
  failing after the first visit; the key, a wrong key or the patient's
  name or ID in the server's output.
- TlsTest: the page not served over HTTPS with a certificate made here, a
  plain-HTTP request answered, the cookie without its Secure flag.
- HostTest: a server beyond loopback without TLS starting without
  --insecure, or silently with it.
The listing, an upload and the PNG with the key are test_web's b, g and h,
which open the page at the printed address.
"""
import asyncio
import os
import re
import shutil
import ssl
import subprocess
import sys
import tempfile
import time
import unittest

import aiohttp
from selenium import webdriver
from selenium.webdriver.chrome.options import Options
from selenium.webdriver.chrome.service import Service

from mmrtm_web.access import COOKIE_LIFETIME_S, REFUSAL, AccessError, AccessKey, read_token_file, tls_context
from mmrtm_web.app import access_settings, parse_arguments
from test_web import CHROMIUM, DRIVER, FRAME_STATISTICS, free_port, printed_address

DATA = os.environ["MMRTM_SHARED_DATA_DIR"]
SCRIPT = shutil.which("mmrtm-web", path=os.path.dirname(sys.executable))
PATIENT_NAME, PATIENT_ID = "Planted^Patient^Name", "PLANTED-ID-4711"


def start_server(arguments, log_path, environment=None):
    """mmrtm-web with `arguments`, its output in `log_path`; the process
    and the address it printed."""
    log = open(log_path, "w")
    server = subprocess.Popen([SCRIPT] + arguments, stdout=log, stderr=subprocess.STDOUT,
                              env=dict(os.environ, **(environment or {})))
    log.close()
    try:
        return server, printed_address(server, log_path)
    except RuntimeError:
        stop(server)
        raise


def stop(server):
    server.terminate()
    try:
        server.wait(timeout=30)
    except subprocess.TimeoutExpired:
        server.kill()
        server.wait()


async def fetch(url, cookies=None, ssl_context=None, websocket=False, headers=None):
    """(status, headers, body) of a GET of `url` (redirects not followed),
    or of a WebSocket handshake when `websocket` (status 101 when it was
    accepted)."""
    jar = aiohttp.CookieJar(unsafe=True)
    async with aiohttp.ClientSession(cookie_jar=jar, cookies=cookies or {}, headers=headers or {}) as session:
        if websocket:
            try:
                async with session.ws_connect(url, ssl=ssl_context or True) as ws:
                    await ws.close()
                    return 101, {}, ""
            except aiohttp.WSServerHandshakeError as e:
                return e.status, dict(e.headers or {}), ""
        async with session.get(url, allow_redirects=False, ssl=ssl_context or True) as response:
            return response.status, response.headers, (await response.read()).decode("utf-8", "replace")


def get(*args, **kwargs):
    return asyncio.run(fetch(*args, **kwargs))


class AccessRulesTest(unittest.TestCase):
    """The key's rules without a server."""

    def test_cookies_end_and_belong_to_their_key(self):
        now = [1_000_000.0]
        key = AccessKey("a-key-of-thirty-two-characters-x", clock=lambda: now[0])
        cookie = key.new_cookie_value()
        self.assertIsNone(key.cookie_refusal(cookie))
        now[0] += COOKIE_LIFETIME_S - 1
        self.assertIsNone(key.cookie_refusal(cookie))
        now[0] += 2
        self.assertEqual(key.cookie_refusal(cookie), "an expired cookie")
        other = AccessKey("another-key-of-thirty-two-chars-", clock=lambda: now[0])
        self.assertEqual(key.cookie_refusal(other.new_cookie_value()), "a cookie of another key")
        # A cookie whose expiry was moved on keeps its old MAC: refused.
        expires, mac = key.new_cookie_value().split(".")
        self.assertEqual(key.cookie_refusal("%d.%s" % (int(expires) + 3600, mac)), "a cookie of another key")
        for damaged in ("", ".", "x.y", cookie[:-1], cookie + "0", "9" * 5000 + ".x"):
            self.assertIsNotNone(key.cookie_refusal(damaged), damaged)
        self.assertNotEqual(key.cookie_name, other.cookie_name)
        self.assertNotIn(key.token.decode(), key.cookie_name + cookie)

    def test_key_files_and_certificates_are_named_when_unusable(self):
        with tempfile.TemporaryDirectory() as folder:
            short = os.path.join(folder, "short.txt")
            with open(short, "w") as f:
                f.write("abc\n")
            for path in (short, os.path.join(folder, "missing.txt")):
                with self.assertRaises(AccessError) as raised:
                    read_token_file(path)
                self.assertIn(path, str(raised.exception))
            good = os.path.join(folder, "key.txt")
            with open(good, "w") as f:
                f.write("0123456789abcdef0123\nignored\n")
            self.assertEqual(read_token_file(good), "0123456789abcdef0123")
            not_a_certificate = os.path.join(folder, "cert.pem")
            with open(not_a_certificate, "w") as f:
                f.write("not a certificate\n")
            for certificate in (not_a_certificate, os.path.join(folder, "missing.pem")):
                with self.assertRaises(AccessError) as raised:
                    tls_context(certificate)
                self.assertIn(certificate, str(raised.exception))

    def test_unsafe_starts_are_refused(self):
        def settings(*arguments, environment=None):
            return access_settings(parse_arguments(["study.nrrd"] + list(arguments)), environment or {})

        token, context = settings()
        self.assertGreaterEqual(len(token), 43, "256 bits, URL-safe base64")
        self.assertNotEqual(token, settings()[0], "a new key at each start")
        self.assertIsNone(context)
        self.assertEqual(settings(environment={"MMRTM_WEB_TOKEN": "0123456789abcdefXYZ"})[0], "0123456789abcdefXYZ")
        for arguments in (["--host", "0.0.0.0"], ["--host", "192.0.2.7"], ["--host", "0.0.0.0", "--no-token"],
                          ["--no-token", "--host", "::"], ["--keyfile", "key.pem"]):
            with self.assertRaises(AccessError, msg=arguments):
                settings(*arguments)
        self.assertIsNotNone(settings("--host", "0.0.0.0", "--insecure")[0], "--insecure keeps the key")
        self.assertEqual(settings("--no-token"), (None, None))
        with self.assertRaises(AccessError):
            settings(environment={"MMRTM_WEB_TOKEN": "short"})


def make_certificate(folder):
    """A self-signed certificate for 127.0.0.1 made with openssl; its
    files (certificate, key)."""
    certificate, key = os.path.join(folder, "cert.pem"), os.path.join(folder, "key.pem")
    subprocess.run(["openssl", "req", "-x509", "-newkey", "rsa:2048", "-nodes", "-days", "1", "-subj", "/CN=127.0.0.1",
                    "-addext", "subjectAltName=IP:127.0.0.1", "-keyout", key, "-out", certificate],
                   check=True, capture_output=True)
    return certificate, key


def without_token(address):
    return re.sub(r"\?token=.*$", "", address)


def token_of(address):
    return re.search(r"\?token=([^&]+)$", address).group(1)


class KeyTest(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        import pydicom

        cls.folder = tempfile.TemporaryDirectory()
        cls.study = os.path.join(cls.folder.name, "chest_series")
        os.mkdir(cls.study)
        for name in os.listdir(os.path.join(DATA, "ct_chest_dicom")):
            dataset = pydicom.dcmread(os.path.join(DATA, "ct_chest_dicom", name))
            dataset.PatientName, dataset.PatientID = PATIENT_NAME, PATIENT_ID
            dataset.save_as(os.path.join(cls.study, name))
        # A file of the data root whose name no refusal may carry.
        shutil.copy(os.path.join(DATA, "ct_head_headsq.nrrd"), os.path.join(cls.folder.name, "second_study.nrrd"))
        cls.log_path = os.path.join(cls.folder.name, "server.log")
        cls.server, cls.address = start_server([cls.study, "--port", str(free_port()), "--maximum-samples", "8"],
                                               cls.log_path)
        cls.base, cls.token = without_token(cls.address), token_of(cls.address)
        cls.key = AccessKey(cls.token)

    @classmethod
    def tearDownClass(cls):
        stop(cls.server)
        cls.folder.cleanup()

    def routes(self):
        """The page, the redirect to it, a script and a picture it loads, an
        unknown path, and the WebSocket."""
        status, _, page = get(self.base + "index.html", cookies={self.key.cookie_name: self.key.new_cookie_value()})
        self.assertEqual(status, 200)
        script = re.search(r'src="\./(assets/[^"]+\.js)"', page).group(1)
        return ["", "index.html", script, "logo.png", "no-such-file", "ws"]

    def assertRefused(self, route, status, headers, body):
        self.assertEqual(status, 403, route)
        if route != "ws":
            self.assertEqual(body, REFUSAL, route)
            self.assertEqual(headers.get("Cache-Control"), "no-store", route)
            for name in ("chest_series", "second_study", ".dcm", ".nrrd", self.folder.name):
                self.assertNotIn(name, body, route)

    def test_every_route_refuses_without_the_key(self):
        expired = AccessKey(self.token, clock=lambda: time.time() - 2 * COOKIE_LIFETIME_S).new_cookie_value()
        another = AccessKey("another-key-of-thirty-two-chars-").new_cookie_value()
        for route in self.routes():
            websocket = route == "ws"
            url = self.base + route
            for why, attempt in (("no key", lambda: get(url, websocket=websocket)),
                                 ("a wrong key", lambda: get(url + "?token=" + self.token[:-1] + "x",
                                                             websocket=websocket)),
                                 ("expired", lambda: get(url, {self.key.cookie_name: expired}, websocket=websocket)),
                                 ("another key's cookie",
                                  lambda: get(url, {self.key.cookie_name: another}, websocket=websocket)),
                                 ("a wrong header", lambda: get(url, websocket=websocket,
                                                                headers={"Authorization": "token x" + self.token}))):
                with self.subTest(route=route, attempt=why):
                    self.assertRefused(route, *attempt())
        # With the key in the address, or its cookie, each route answers.
        cookie = {self.key.cookie_name: self.key.new_cookie_value()}
        for route in self.routes():
            with self.subTest(route=route, attempt="with the key"):
                websocket = route == "ws"
                status, _, _ = get(self.base + route, cookie, websocket=websocket)
                self.assertEqual(status, {"": 302, "ws": 101, "no-such-file": 404}.get(route, 200), route)
        self.assertEqual(get(self.base + "ws?token=" + self.token, websocket=True)[0], 101)
        # A reverse proxy's (or a script's) header.
        proxy = {"Authorization": "token " + self.token}
        self.assertEqual(get(self.base + "index.html", headers=proxy)[0], 200)
        self.assertEqual(get(self.base + "ws", headers=proxy, websocket=True)[0], 101)

    def test_the_key_becomes_a_cookie_that_scripts_cannot_read(self):
        status, headers, _ = get(self.address)
        self.assertEqual(status, 302)
        self.assertEqual(headers["Location"], "/", "the key leaves the address")
        cookie = headers["Set-Cookie"]
        self.assertTrue(cookie.startswith(self.key.cookie_name + "="), cookie)
        for flag in ("HttpOnly", "SameSite=Strict", "Path=/", "Max-Age=%d" % COOKIE_LIFETIME_S):
            self.assertIn(flag, cookie)
        self.assertNotIn("Secure", cookie, "plain HTTP: a Secure cookie would not come back")
        self.assertNotIn(self.token, cookie)
        # Other parameters of the address stay.
        self.assertEqual(get(self.base + "index.html?ui=main&token=" + self.token)[1]["Location"],
                         "/index.html?ui=main")

    def test_the_log_holds_neither_keys_nor_the_patient(self):
        get(self.base + "index.html?token=wrong-key-that-must-not-be-logged")
        get(self.base + "index.html")
        get(self.base + "a%0amade-up%20line")
        time.sleep(0.5)
        with open(self.log_path) as f:
            log = f.read()
        self.assertIn("refused GET /index.html from 127.0.0.1: a wrong key", log)
        self.assertIn("refused GET /index.html from 127.0.0.1: no key", log)
        self.assertNotIn("wrong-key-that-must-not-be-logged", log)
        self.assertIn("refused GET /a?made-up line from", log, "a path's line break is not a line of the log")
        self.assertEqual(log.count(self.token), 1, "the key only in the printed address")
        for planted in (PATIENT_NAME, PATIENT_ID, "Planted", "4711"):
            self.assertNotIn(planted, log)

    def test_chromium_opens_the_printed_address_and_then_needs_no_key(self):
        options = Options()
        for argument in ("--headless=new", "--no-sandbox", "--disable-dev-shm-usage", "--window-size=1000,700"):
            options.add_argument(argument)
        options.binary_location = CHROMIUM
        browser = webdriver.Chrome(service=Service(DRIVER), options=options)
        try:
            # Without the key: only the refusal, no page.
            browser.get(self.base)
            self.assertEqual(browser.find_element("tag name", "body").text.strip(), REFUSAL.strip())
            self.assertEqual(browser.find_elements("tag name", "img"), [])
            for address in (self.address, self.base):  # the printed address, then a reload without the key
                browser.get(address)
                self.assertTrue(browser.current_url.startswith(self.base), browser.current_url)
                self.assertNotIn("token", browser.current_url, "the key is not left in the address bar")
                deadline, statistics = time.monotonic() + 90, None
                while time.monotonic() < deadline and not (statistics and statistics[0] > 100):
                    time.sleep(0.25)
                    statistics = browser.execute_script(FRAME_STATISTICS, False)
                self.assertTrue(statistics and statistics[0] > 100, "a 3D frame at %s" % without_token(address))
                self.assertGreater(statistics[2], 0.02, "the study in view")
            self.assertEqual(browser.execute_script("return document.cookie"), "", "HttpOnly")
        finally:
            browser.quit()


class TlsTest(unittest.TestCase):
    def test_https_with_a_certificate_made_here_and_plain_http_refused(self):
        with tempfile.TemporaryDirectory() as folder:
            certificate, key = make_certificate(folder)
            log_path = os.path.join(folder, "server.log")
            port = free_port()
            server, address = start_server([os.path.join(DATA, "ct_head_headsq.nrrd"), "--port", str(port),
                                            "--certfile", certificate, "--keyfile", key], log_path)
            try:
                self.assertTrue(address.startswith("https://127.0.0.1:%d/?token=" % port), address)
                trusted = ssl.create_default_context(cafile=certificate)
                status, headers, _ = get(address, ssl_context=trusted)
                self.assertEqual(status, 302)
                self.assertIn("Secure", headers["Set-Cookie"])
                cookie = {AccessKey(token_of(address)).cookie_name: AccessKey(token_of(address)).new_cookie_value()}
                status, _, page = get(without_token(address) + "index.html", cookie, ssl_context=trusted)
                self.assertEqual(status, 200)
                self.assertIn("<html", page)
                self.assertEqual(get(without_token(address) + "ws", cookie, ssl_context=trusted, websocket=True)[0],
                                 101)
                with self.assertRaises(aiohttp.ClientError, msg="plain HTTP on the TLS port"):
                    get("http://127.0.0.1:%d/?token=%s" % (port, token_of(address)))
                with self.assertRaises(aiohttp.ClientError, msg="a certificate the client does not trust"):
                    get(address)
            finally:
                stop(server)


class HostTest(unittest.TestCase):
    def test_beyond_loopback_needs_tls_or_insecure(self):
        study = os.path.join(DATA, "ct_head_headsq.nrrd")
        refused = subprocess.run([SCRIPT, study, "--host", "0.0.0.0", "--port", str(free_port())],
                                 capture_output=True, text=True, timeout=120)
        self.assertNotEqual(refused.returncode, 0)
        self.assertIn("--host 0.0.0.0 serves beyond this machine", refused.stderr)
        self.assertNotIn("Traceback", refused.stderr)
        with tempfile.TemporaryDirectory() as folder:
            log_path = os.path.join(folder, "server.log")
            server, address = start_server([study, "--host", "0.0.0.0", "--insecure", "--port", str(free_port())],
                                           log_path)
            try:
                with open(log_path) as f:
                    self.assertIn("warning: serving on 0.0.0.0 without TLS", f.read())
                self.assertIn("?token=", address, "--insecure keeps the key")
                port = int(re.search(r":(\d+)/", address).group(1))
                self.assertEqual(get("http://127.0.0.1:%d/" % port)[0], 403)
            finally:
                stop(server)


if __name__ == "__main__":
    unittest.main()
