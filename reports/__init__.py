"""The report and notebook templates, shipped inside the wheel as ``gcodekit.reports``.

``program.html``, ``index.html``, ``error.html`` and ``base.html`` (with
``style.css``) are the Jinja2 pages of ``gcodekit report``;
``program_report.ipynb`` is the same report as a notebook (``--notebook``).
Edit them here; :mod:`gcodekit.report` reads them with
:mod:`importlib.resources`, so they work from a built wheel as from this
checkout.
"""
