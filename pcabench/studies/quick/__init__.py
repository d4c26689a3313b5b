"""The default study: the paper's tables and figures at small N (``pcabench study``); the study ``paper``
reports it."""
