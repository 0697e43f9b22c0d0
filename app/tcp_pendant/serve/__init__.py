"""The serving layer: the ``tcp-pendant`` command and what runs the web app.

``cli`` (the command and its subcommands), ``server`` (``PendantApp``: the viser server, one
session per browser, the class room handed its view builders), ``workers`` and ``balance``
(``--workers N``: the processes on one port and which takes a new connection), ``origin_check``
and ``addresses`` (the Host allow-list and websocket Origin check; the URLs to tell a class),
``client_script`` with ``static/pendant.js`` (our page script), ``poses_import_cli``
(``tcp-pendant poses import``). The top layer of the app: it may import every package below it
(``pyproject.toml`` ``[tool.importlinter]``) and nothing imports it but ``tcp_pendant.__main__``.
"""
