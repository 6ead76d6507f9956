from hsgplan.cli import main

main()
