"""wmrkit studio: design a robot in the browser and see its kinematics live (``wmrkit studio``, docs/studio.md).

:mod:`.api` holds the endpoints as pure functions (JSON in, JSON out, every number from the library),
:mod:`.files` the file access confined to one directory, :mod:`.app` the Starlette application; Starlette and
uvicorn (the 'studio' extra) are imported only by :func:`wmrkit.studio.app.create_app`.
"""
