"""Output shared by the benchmark scripts (frame.py, animation.py): a part's Markdown tables on
stdout and in a file, and its rows and targets as JSON for run.sh's summary (summary.py)."""

import json


def publish(markdown, markdown_path=None, json_path=None, data=None):
    print(markdown)
    if markdown_path:
        with open(markdown_path, "w") as f:
            f.write(markdown)
    if json_path:
        with open(json_path, "w") as f:
            json.dump(data, f, indent=1)
