"""A robot that speaks petriflow's remote-action protocol over MQTT, in plain Python.

It imports no petriflow (only paho-mqtt), as firmware on an ESP8266 would not: it
announces itself, beats, accepts goals once per id, and answers with a result.

    python examples/plain_robot_mqtt.py --name blinky --port 1883
"""
import argparse
import json
import threading
import time
import uuid

import paho.mqtt.client as mqtt

ACTIONS = {"robot.blink": {"times": {"type": "int", "default": 3}},  # what this robot can do
           "robot.beep": {"hz": {"type": "float"}}}


def main() -> None:
    parser = argparse.ArgumentParser()
    parser.add_argument("--name", required=True)
    parser.add_argument("--host", default="127.0.0.1")
    parser.add_argument("--port", type=int, default=1883)
    args = parser.parse_args()
    inbox, outbox = f"petriflow/v1/to/{args.name}", f"petriflow/v1/from/{args.name}"
    instance, answers, running, lock = uuid.uuid4().hex, {}, {}, threading.Lock()

    def send(kind, **fields):
        client.publish(outbox, json.dumps({"v": 1, "type": kind, "agent": args.name, **fields}), qos=1)

    def work(goal):  # the hardware's part: here, blinking takes 0.1 s a blink
        time.sleep(0.1 * int(goal["params"].get("times", 3)))
        with lock:
            if running.pop(goal["id"], None) is None:  # cancelled meanwhile
                return
            answers[goal["id"]] = {"outcome": "ok", "data": {"blinked": goal["params"].get("times", 3)}}
        send("result", id=goal["id"], **answers[goal["id"]])

    def on_message(client, userdata, message):
        try:
            msg = json.loads(message.payload)
            kind, goal_id = msg["type"], msg.get("id")
        except (ValueError, KeyError, TypeError):
            return  # not for us: dropped
        if msg.get("v") != 1 or kind not in ("goal", "cancel"):
            return
        with lock:
            if goal_id in answers:  # sent again: the same answer, never a second run
                send("result" if "outcome" in answers[goal_id] else "cancelled", id=goal_id, **answers[goal_id])
                return
            if kind == "cancel":
                running.pop(goal_id, None)
                answers[goal_id] = {}
                send("cancelled", id=goal_id)
                return
            if goal_id in running:
                send("accepted", id=goal_id)
                return
            if msg.get("action") not in ACTIONS:
                send("rejected", id=goal_id, reason=f"no action {msg.get('action')!r} here")
                return
            running[goal_id] = msg
        send("accepted", id=goal_id)
        threading.Thread(target=work, args=(msg,), daemon=True).start()

    def on_connect(client, userdata, flags, reason, properties=None):
        client.subscribe(inbox, qos=1)
        send("announce", actions=ACTIONS, instance=instance)

    client = mqtt.Client(mqtt.CallbackAPIVersion.VERSION2, client_id=f"{args.name}-{instance[:8]}")
    client.on_connect, client.on_message = on_connect, on_message
    client.connect(args.host, args.port)
    client.loop_start()
    beats = 0
    while True:  # heartbeats, and an announcement every two seconds
        time.sleep(0.5)
        beats += 1
        with lock:
            ids = list(running)
        send("heartbeat", running=ids, instance=instance)
        if beats % 4 == 0:
            send("announce", actions=ACTIONS, instance=instance)


if __name__ == "__main__":
    main()
