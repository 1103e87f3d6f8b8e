import sys

try:
    from fracid.cli import main
except KeyboardInterrupt:  # Ctrl-C while the command starts: nothing computed yet
    import signal

    signal.signal(signal.SIGINT, signal.SIG_IGN)
    print("fracid: interrupted while starting; nothing was computed.", file=sys.stderr)
    sys.exit(130)

sys.exit(main())
