"""The paper's own tables and figures (Tables 4-6, Figs. 8-14): ``pcabench study --paper``; its sections
(one module each, listed in section.py) also report the default study ``quick``."""
