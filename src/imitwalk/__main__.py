"""``python -m imitwalk`` runs the command-line tool."""

from imitwalk.cli.main import main

raise SystemExit(main())
