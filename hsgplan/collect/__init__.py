"""The four collections, each a resumable command (`hsgplan collect ...`): the paper's
demonstrations (`demos`), self-supervised motion data (`motion`), f_reach's executed primitives
(`reach`) and f_p's synthetic images (`images`). Their formats, which training reads, live
with the data (`data/demos.py`, `data/motion_store.py`, `data/world_trials.py`,
`perception/images.py`)."""
