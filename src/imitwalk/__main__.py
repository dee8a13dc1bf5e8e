"""``python -m imitwalk`` runs the command-line tool."""

from imitwalk.cli import main

raise SystemExit(main())
