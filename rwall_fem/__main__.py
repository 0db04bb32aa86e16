from rwall_fem.cli import main

raise SystemExit(main())
