mod rtps_support;
use std::time::Duration;
use dds_runtime::qos::*;
use dds_runtime::rtps::*;
use dds_runtime::rtps::messages::*;
use rtps_support::*;
#[test]
fn dbg() {
    let mut sim = Sim::with_participants(1, Faults::NONE, 2);
    let now = sim.now;
    let w = sim.nodes[0].p.create_writer(now, WriterSpec::new("T", "T", false, DataWriterQos::builder().reliability(Reliability::BestEffort).build())).unwrap();
    let _r = sim.nodes[1].p.create_reader(now, ReaderSpec::new("T", "T", false, DataReaderQos::default())).unwrap();
    sim.run_for(Duration::from_millis(100));
    for k in 0..2 {
    for i in 0..200 {
        let now = sim.now;
        while let Some(t) = sim.nodes[i%2].p.poll_transmit(now) {
            let (h, it) = MessageIter::parse(&t.payload).unwrap();
            let subs: Vec<String> = it.map(|s| match s.unwrap() { Submessage::Data(d) => format!("DATA {:?}->{:?} sn{}", d.writer_id, d.reader_id, d.writer_sn.0), x => format!("{:?}", x).chars().take(100).collect() }).collect();
            println!("{:?} {:?} from {:?} to {:?}: {:?}", sim.now - sim.start, k, h.guid_prefix, t.destinations, subs);
            for n in 0..2 { sim.nodes[n].p.handle_datagram(now, &t.payload); }
        }
        if i == 100 && k == 1 { sim.nodes[0].p.write(now, w, WriteChange::alive(vec![0,1,0,0,0,0,0,0])).unwrap(); }
        let next = sim.nodes.iter().filter_map(|n| n.p.poll_timeout()).min().unwrap();
        sim.now = next.max(sim.now);
        for n in 0..2 { let now = sim.now; sim.nodes[n].p.handle_timeout(now); }
    }
    }
    panic!();
}
