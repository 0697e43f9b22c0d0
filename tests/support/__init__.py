"""What the tests share, imported as ``support.*`` (pyproject.toml's pytest ``pythonpath`` puts
``tests/`` on ``sys.path``; a benchmark run as a script gets it from
``tests/bench/_tests_on_path.py``).

* ``fixtures``: the pytest fixtures of every folder (registered by ``tests/conftest.py``): a
  pendant in this process (``app_factory``), a browser on it (``page``), a pendant in a
  subprocess (``pendant_server``), chromium (``browser``, ``new_page``, ``shot``).
* Headless browsers: ``wsclient`` (websocket clients speaking viser's protocol, the barriers
  ``DrainingClient.sync`` and ``loop_ran_for``), ``async_clients`` (many of them in one process),
  ``guiclick`` (a browser's click as a GUI event), ``app_page`` and ``calib_page`` (one connected
  browser and its views).
* Chromium: ``chromium_session``, ``pendant_page`` and ``wizard_page`` (Playwright helpers),
  ``server_process`` (``python -m tcp_pendant`` in a subprocess).
* Rigs: ``browser_flood`` and ``job_attack`` (the security tests' and ``bench_jobs.py``'s loads).
* Data and doubles: ``poses`` and ``angle_reference`` (touch sets, exact angle figures),
  ``cli_runs`` (the ``tcpcal`` CLI on CSV files), ``calib_helpers`` (controllers and sessions as
  the app builds them), ``fake_controller`` (auto-touch's test double), ``jogging`` (a fake
  clock and scheduler), ``ros_layouts`` (ROS-Industrial robot layouts).
"""
