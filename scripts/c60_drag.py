#!/usr/bin/env python3
"""Drives the C-60 as a user dragging its interactive markers in RViz would, and grabs
the screen: the driver of scripts/c60_drag.sh (record_video.sh --drive).

    c60_drag.py OUTPUT_PREFIX WxH DISPLAY

The node (config/c60.yaml, paused) is stepped with ~step, so each frame is at a known
sim time. After 2 ms at rest the probe's marker is dragged along its bore 0.5 mm
further per frame up to 3 mm (InteractiveMarkerFeedback on the markers' feedback
topic, as RViz sends it), and the node steps 1 ms per frame: the probe follows at the
node's rate limit (0.2 m/s), touches the bar, releases the latch, C7 opens. Writes
OUTPUT_PREFIX.gif (one frame per ms, the mechanism's part of the screen, 560 px wide) and OUTPUT_PREFIX.png (the frame
after the release, full size).
"""
import copy
import os
import shutil
import subprocess
import sys
import tempfile
import time

import rospy
from nscd_sim.msg import KeyFigures
from nscd_sim.srv import Step
from visualization_msgs.msg import InteractiveMarkerFeedback, InteractiveMarkerInit

SERVER = '/nscd_actuator_markers'
NODE = '/nscd_sim_node'


def main():
    prefix, size, display = sys.argv[1:4]
    rospy.init_node('c60_drag', anonymous=True, disable_signals=True)
    init = rospy.wait_for_message(SERVER + '/update_full', InteractiveMarkerInit, 60)
    probe = next(m for m in init.markers if m.name == 'probe')
    feedback = rospy.Publisher(SERVER + '/feedback', InteractiveMarkerFeedback, queue_size=10)
    while feedback.get_num_connections() == 0:
        time.sleep(0.05)
    rospy.wait_for_service(NODE + '/step', 30)
    step = rospy.ServiceProxy(NODE + '/step', Step)
    figures = {}

    def on_figures(m):
        figures.update(zip(m.names, m.values))
        figures['t'] = m.sim_time
    rospy.Subscriber(NODE + '/key_figures', KeyFigures, on_figures)

    def send(event, travel):
        f = InteractiveMarkerFeedback()
        f.header.frame_id = probe.header.frame_id
        f.client_id = '/c60_drag/InteractiveMarkers'
        f.marker_name = 'probe'
        f.control_name = 'slide'
        f.event_type = event
        f.pose = copy.deepcopy(probe.pose)
        f.pose.position.x = probe.pose.position.x + travel  # the bore is along world +x
        feedback.publish(f)
        time.sleep(0.1)

    def advance(seconds):
        t0 = figures.get('t', 0.0)
        r = step(int(round(seconds / 1e-6)))  # config/c60.yaml: dt 1e-6
        if not r.success:
            sys.exit('c60_drag.py: ~step failed: ' + r.message)
        return r.sim_time

    tmp = tempfile.mkdtemp(prefix='c60_drag.')
    frames = []

    def grab(label):
        time.sleep(3.0)  # RViz draws the last state and the marker's new text
        path = os.path.join(tmp, 'frame_%02d.png' % len(frames))
        subprocess.run(['ffmpeg', '-nostdin', '-y', '-loglevel', 'error', '-f', 'x11grab', '-draw_mouse', '0',
                        '-video_size', size, '-i', display, '-frames:v', '1', path], check=True)
        frames.append(path)
        print('c60_drag.py: frame %d: %s; probe.cmd %.3f mm, TRIP.fn %.2f N, C7.fn %.2f N'
              % (len(frames) - 1, label, 1e3 * figures.get('probe.cmd', float('nan')),
                 figures.get('TRIP.fn', float('nan')), figures.get('C7.fn', float('nan'))), file=sys.stderr)

    t = advance(0.002)
    grab('t = %.1f ms, at rest' % (1e3 * t))
    send(InteractiveMarkerFeedback.MOUSE_DOWN, 0.0)
    released = None
    for k in range(1, 14):
        target = min(0.0005 * k, 0.003)
        send(InteractiveMarkerFeedback.POSE_UPDATE, target)
        if k == 6:
            send(InteractiveMarkerFeedback.MOUSE_UP, target)
        t = advance(0.001)
        grab('t = %.1f ms, dragged to %.1f mm' % (1e3 * t, 1e3 * target))
        if released is None and figures.get('C7.fn', 1.0) == 0.0:
            released = len(frames) - 1
    # The GIF: 1.5 frames a second; of a 1280x720 screen the part with the mechanism and
    # the texts (700x560 from x 180, y 62), scaled to 80 %; one palette for all frames.
    gif, png = prefix + '.gif', prefix + '.png'
    pattern = os.path.join(tmp, 'frame_%02d.png')
    crop = 'crop=700:560:180:62,' if size == '1280x720' else ''
    subprocess.run(['ffmpeg', '-nostdin', '-y', '-loglevel', 'error', '-framerate', '1.5', '-i', pattern,
                    '-vf', crop + 'scale=560:-1:flags=lanczos,split[a][b];[a]palettegen=max_colors=64[p];'
                    '[b][p]paletteuse=dither=none', '-loop', '0', gif], check=True)
    last = frames[released if released is not None else -1]
    subprocess.run(['ffmpeg', '-nostdin', '-y', '-loglevel', 'error', '-i', last, png], check=True)
    shutil.rmtree(tmp)
    print('c60_drag.py: %s (%d frames), %s' % (gif, len(frames), png), file=sys.stderr)


if __name__ == '__main__':
    main()
