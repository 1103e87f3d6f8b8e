import sys

from fracid.cli import main

sys.exit(main())
