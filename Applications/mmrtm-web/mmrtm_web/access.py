"""Who may use the server: the holder of its access key.

The key is a random token made at start (256 bits), or the one a
deployment gives (--token-file, MMRTM_WEB_TOKEN). Every HTTP request and
every WebSocket handshake passes one check (an aiohttp middleware in front
of all of trame's and wslink's routes: the page, its scripts, the
WebSocket that carries the studies' listing, uploads and the PNG): the key
in the address (?token=...), the cookie a first visit with the key leaves,
or an "Authorization: token KEY" header (what a reverse proxy in front
adds). The cookie holds no key: an expiry and a keyed MAC of it, so that it
ends, and a cookie of another key or another server is refused. Keys and
MACs are compared in constant time; a refusal is logged without what was
given, and its body names no file. Jupyter's server is the model (a token
by default, printed in the URL the user opens, a cookie after).
"""
import hashlib
import hmac
import os
import secrets
import ssl
import sys
import time

TOKEN_ENVIRONMENT = "MMRTM_WEB_TOKEN"
# Shorter keys could be guessed; 16 characters of a random key hold 96 bits
# and more.
SHORTEST_TOKEN = 16
# How long a visit with the key lets a browser in without it: a working
# day; after that the printed URL is needed again.
COOKIE_LIFETIME_S = 12 * 3600

REFUSAL = ("mmrtm-web: this server needs its access key. Open the address it printed when it started "
           "(it ends in ?token=...), or ask whoever runs it.\n")


class AccessError(ValueError):
    pass


def make_token():
    return secrets.token_urlsafe(32)


def read_token_file(path):
    """The key in the first line of `path`; AccessError naming the file when
    it cannot be read or is too short to be a key."""
    try:
        with open(path, encoding="utf-8") as f:
            token = f.readline().strip()
    except (OSError, UnicodeDecodeError) as e:
        raise AccessError("--token-file %s: %s" % (path, e.strerror if isinstance(e, OSError) else e)) from e
    if len(token) < SHORTEST_TOKEN:
        raise AccessError("--token-file %s: its first line is not a key of at least %d characters"
                          % (path, SHORTEST_TOKEN))
    return token


def chosen_token(token_file=None, environment=os.environ):
    """The deployment's key (the file first, then the environment), or a new
    random one; AccessError on a bad one."""
    if token_file:
        return read_token_file(token_file)
    given = environment.get(TOKEN_ENVIRONMENT, "")
    if given:
        if len(given.strip()) < SHORTEST_TOKEN:
            raise AccessError("%s is not a key of at least %d characters" % (TOKEN_ENVIRONMENT, SHORTEST_TOKEN))
        return given.strip()
    return make_token()


def tls_context(certfile, keyfile=None):
    """A server's TLS context from a certificate (and its key, when it is in
    a file of its own); AccessError naming the file when either cannot be
    used."""
    context = ssl.SSLContext(ssl.PROTOCOL_TLS_SERVER)
    context.minimum_version = ssl.TLSVersion.TLSv1_2
    for path, flag in ((certfile, "--certfile"), (keyfile, "--keyfile")):
        if path and not os.path.isfile(path):
            raise AccessError("%s %s: no such file" % (flag, path))
    try:
        context.load_cert_chain(certfile, keyfile)
    except (ssl.SSLError, OSError) as e:
        raise AccessError("--certfile %s%s: not a certificate and its private key (%s)"
                          % (certfile, " --keyfile %s" % keyfile if keyfile else "", e)) from e
    return context


class AccessKey:
    """The key and the checks made with it (see the module's text)."""

    def __init__(self, token, secure_cookie=False, log=None, clock=time.time):
        self.token = token.encode("utf-8")
        self.secure_cookie = secure_cookie
        self.log = log or (lambda line: print(line, file=sys.stderr, flush=True))
        self.clock = clock
        # Cookies are shared by every port of a host: the name tells this
        # key's cookie from another server's (a hash, which reveals nothing
        # of the key).
        self.cookie_name = "mmrtm-web-" + hashlib.sha256(self.token).hexdigest()[:12]

    def matches(self, given):
        return hmac.compare_digest(self.token, given.encode("utf-8"))

    def cookie_value(self, expires):
        mac = hmac.new(self.token, b"mmrtm-web cookie %d" % expires, hashlib.sha256).hexdigest()
        return "%d.%s" % (expires, mac)

    def new_cookie_value(self):
        return self.cookie_value(int(self.clock()) + COOKIE_LIFETIME_S)

    def cookie_refusal(self, value):
        """Why the cookie's value lets nobody in, or None when it is valid."""
        expires = value.partition(".")[0]
        # A cookie of this server's has a ten-digit expiry; longer digits
        # are not even read as a number.
        if not expires.isdigit() or len(expires) > 12 or not hmac.compare_digest(
                self.cookie_value(int(expires)).encode(), value.encode("utf-8", "replace")):
            return "a cookie of another key"
        if int(expires) < self.clock():
            return "an expired cookie"
        return None

    def refusal(self, request):
        """Why `request` is refused, or None when it holds the key or a valid
        cookie."""
        given = request.query.get("token")
        if given is not None:
            return None if self.matches(given) else "a wrong key"
        scheme, _, given = request.headers.get("Authorization", "").partition(" ")
        if scheme.lower() == "token":
            return None if self.matches(given.strip()) else "a wrong key in the Authorization header"
        cookie = request.cookies.get(self.cookie_name)
        if cookie is not None:
            return self.cookie_refusal(cookie)
        return "no key"

    def middleware(self):
        """The aiohttp middleware that checks every request."""
        from aiohttp import hdrs, web

        @web.middleware
        async def check_access_key(request, handler):
            why = self.refusal(request)
            if why is not None:
                # The path without the query (a wrong key is not written
                # to the log either), its unprintable characters replaced
                # (a path cannot write lines of its own into the log).
                path = "".join(c if c.isprintable() else "?" for c in request.path)
                self.log("mmrtm-web: refused %s %s from %s: %s" % (request.method, path, request.remote, why))
                raise web.HTTPForbidden(text=REFUSAL, headers={hdrs.CACHE_CONTROL: "no-store"})
            if "token" in request.query and request.method == "GET" and \
                    request.headers.get(hdrs.UPGRADE, "").lower() != "websocket":
                # The key leaves the address bar (and the history) for a
                # cookie: the same address without it.
                query = request.query.copy()
                del query["token"]
                response = web.HTTPFound(request.rel_url.with_query(query))
                self.set_cookie(response)
                raise response
            return await handler(request)

        return check_access_key

    def set_cookie(self, response):
        response.set_cookie(self.cookie_name, self.new_cookie_value(), max_age=COOKIE_LIFETIME_S, path="/",
                            httponly=True, samesite="Strict", secure=self.secure_cookie)
