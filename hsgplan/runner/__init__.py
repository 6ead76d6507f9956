"""The resumable runner every long job shares: engines (process pool or Ray), run folders, and
work items run once each (`hsgplan.runner.items`)."""
