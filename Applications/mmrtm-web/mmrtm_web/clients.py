"""The browsers connected to the server, counted by their WebSocket
connections.

Every browser with the key sees the same study and the same view, and any
of them may drive it (a shared screen: the last action wins). A browser is
counted from its WebSocket's handshake to its close, whatever ends it (a
closed tab, a reload, a crash, a dropped network): trame's own
client_exited message comes from the page's beforeunload only, and a
browser that vanishes without sending it would be counted forever.
Listeners hear when a page is ready (trame's client_connected, sent once
the page has subscribed to the view's frames: the frame rendered then
reaches it) and when a browser leaves; the 3D view's scheduler then ends a
drag left without its button's release, which would otherwise hold every
other browser's view in its low-resolution preview.
"""


class ClientPresence:
    """How many browsers have the page open."""

    def __init__(self, server):
        self.count = 0
        self.arrival_listeners = []
        self.departure_listeners = []
        server.controller.on_client_connected.add(self.page_ready)

    def page_ready(self):
        for listener in self.arrival_listeners:
            listener()

    def arrived(self):
        self.count += 1

    def departed(self):
        self.count -= 1
        for listener in self.departure_listeners:
            listener()

    def __bool__(self):
        return self.count > 0

    def middleware(self):
        """The aiohttp middleware that counts WebSocket connections: their
        handler returns when the connection closes."""
        from aiohttp import hdrs, web

        @web.middleware
        async def count_websockets(request, handler):
            if request.headers.get(hdrs.UPGRADE, "").lower() != "websocket":
                return await handler(request)
            self.arrived()
            try:
                return await handler(request)
            finally:
                self.departed()

        return count_websockets
