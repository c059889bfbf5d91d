#!/usr/bin/python3
"""The rosbag round trip of docs/node.md, two halves (run by rosbag_roundtrip.sh):

  rosbag_roundtrip.py drive SIM_TIME   steps the paused node (~step, 0.1 ms a call)
                                       to SIM_TIME, one publication per call
  rosbag_roundtrip.py check BAG        while c60_playback.launch plays BAG: every
                                       topic RViz shows arrives, and the key figures,
                                       status texts and event labels that arrive are
                                       the recorded ones, value for value
"""
import sys
import time

import rospy


def drive(target):
    from nscd_sim.srv import Step
    rospy.init_node('roundtrip_drive', anonymous=True, disable_signals=True)
    rospy.wait_for_service('/nscd_sim_node/step', 30)
    step = rospy.ServiceProxy('/nscd_sim_node/step', Step)
    # 0.1 ms of sim time a call, whatever the configured dt: the first call's one step
    # tells the dt.
    r = step(1)
    if not r.success:
        sys.exit('FAIL: ~step: ' + r.message)
    steps_per_call = max(1, int(round(1e-4 / r.sim_time)))
    t = r.sim_time
    while t < target - 1e-9:
        r = step(steps_per_call)
        if not r.success:
            sys.exit('FAIL: ~step: ' + r.message)
        t = r.sim_time
        time.sleep(0.05)
    print('drove the node to t = %.6f s' % t)


def key(m):
    return (round(m.sim_time, 12), m.steps, tuple(m.values))


def marker_texts(m):
    return tuple(sorted((x.ns, x.id, x.text) for x in m.markers if x.text))


def check(bag_path):
    import rosbag
    from nscd_sim.msg import KeyFigures
    from rosgraph_msgs.msg import Clock
    from sensor_msgs.msg import JointState
    from tf2_msgs.msg import TFMessage
    from visualization_msgs.msg import Marker, MarkerArray

    rec = {'kf': [], 'status': set(), 'markers': set(), 'counts': {}}
    names = None
    with rosbag.Bag(bag_path) as bag:
        end = bag.get_end_time()
        for topic, m, _ in bag.read_messages():
            rec['counts'][topic] = rec['counts'].get(topic, 0) + 1
            if topic.endswith('/key_figures'):
                rec['kf'].append(key(m))
                names = list(m.names)
            elif topic.endswith('/status'):
                rec['status'].add(m.text)
            elif topic.endswith('/contact_markers'):
                rec['markers'].add(marker_texts(m))
    print('recorded:', ', '.join('%s %d' % kv for kv in sorted(rec['counts'].items())),
          '; bag end %.6f s' % end)
    fail = []
    for t in ('/tf', '/joint_states', '/nscd_sim_node/key_figures', '/nscd_sim_node/contact_markers',
              '/nscd_sim_node/status'):
        if rec['counts'].get(t, 0) < 5:
            fail.append('bag: %d messages on %s' % (rec['counts'].get(t, 0), t))
    if not rec['kf'] or max(k[0] for k in rec['kf']) < 0.0095:
        fail.append('bag: the key figures do not reach 9.5 ms of sim time')
    if fail:
        sys.exit('FAIL: ' + '; '.join(fail))

    got = {'kf': [], 'status': [], 'markers': [], 'tf': 0, 'js': 0, 'clock': 0.0}
    rospy.init_node('roundtrip_check', anonymous=True, disable_signals=True)
    subs = [
        rospy.Subscriber('/nscd_sim_node/key_figures', KeyFigures,
                         lambda m: got['kf'].append((key(m), list(m.names))), queue_size=1000),
        rospy.Subscriber('/nscd_sim_node/status', Marker, lambda m: got['status'].append(m.text),
                         queue_size=1000),
        rospy.Subscriber('/nscd_sim_node/contact_markers', MarkerArray,
                         lambda m: got['markers'].append(marker_texts(m)), queue_size=1000),
        rospy.Subscriber('/tf', TFMessage, lambda m: got.__setitem__('tf', got['tf'] + 1), queue_size=1000),
        rospy.Subscriber('/joint_states', JointState, lambda m: got.__setitem__('js', got['js'] + 1),
                         queue_size=1000),
        rospy.Subscriber('/clock', Clock, lambda m: got.__setitem__('clock', max(got['clock'], m.clock.to_sec())),
                         queue_size=1000),
    ]
    deadline = time.time() + 40
    # rosbag play publishes /clock at 100 Hz of its own (wall) time: the last tick can
    # fall short of the bag's end by up to 1 % of a second of bag time at -r 0.01.
    clock_tol = 2e-4
    while time.time() < deadline and (got['clock'] < end - clock_tol or len(got['kf']) < len(rec['kf'])):
        time.sleep(0.1)
    time.sleep(0.5)
    for s in subs:
        s.unregister()
    kf = got['kf']
    print('played back: key_figures %d, status %d, contact_markers %d, tf %d, joint_states %d, clock up to %.6f s'
          % (len(kf), len(got['status']), len(got['markers']), got['tf'], got['js'], got['clock']))
    if len(kf) < 0.9 * len(rec['kf']):
        fail.append('%d of %d key-figure messages arrived' % (len(kf), len(rec['kf'])))
    recorded = set(rec['kf'])
    bad = [k for k, _ in kf if k not in recorded]
    if bad:
        fail.append('%d key-figure messages differ from every recorded one (first: t=%g)' % (len(bad), bad[0][0]))
    if kf and kf[-1][0] != rec['kf'][-1]:
        fail.append('the last key figures played back are not the last recorded')
    if kf and kf[0][1] != names:
        fail.append('figure names differ')
    if not got['status'] or any(s not in rec['status'] for s in got['status']):
        fail.append('status texts: %d arrived, not all recorded' % len(got['status']))
    if not got['markers'] or any(m not in rec['markers'] for m in got['markers']):
        fail.append('contact markers: %d arrived, not all recorded' % len(got['markers']))
    if not any('latch released' in x[2] for m in got['markers'] for x in m if x[0] == 'events'):
        fail.append('no "latch released" event label played back')
    if got['tf'] == 0 or got['js'] == 0:
        fail.append('no /tf or /joint_states')
    if got['clock'] < end - clock_tol:
        fail.append('/clock reached %.6f s, the bag ends at %.6f s' % (got['clock'], end))
    if fail:
        sys.exit('FAIL: ' + '; '.join(fail))
    print('ok: the played-back messages are the recorded ones')


if __name__ == '__main__':
    if len(sys.argv) != 3 or sys.argv[1] not in ('drive', 'check'):
        sys.exit(__doc__)
    drive(float(sys.argv[2])) if sys.argv[1] == 'drive' else check(sys.argv[2])
