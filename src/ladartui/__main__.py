from ladartui.cli import main

raise SystemExit(main())
