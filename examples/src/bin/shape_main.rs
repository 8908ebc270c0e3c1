//! `shape_main`: the OMG DDS interoperability suite's test program (omg-dds/dds-rtps) on our DCPS API.
//! Same command line, same printed lines, same exit codes (1: bad arguments, 2: initialisation failed,
//! 3: run failed). Options the stack cannot honour yet print a line containing `not supported`.

use std::collections::HashMap;
use std::process::ExitCode;
use std::time::Duration;

use dds_examples::shape_motion::{Motion, WORLD_HEIGHT, WORLD_WIDTH};
use dds_examples::shape_opts::{
    self, AccessScope, DurabilityArg, FinalInstanceState, Parsed, ShapeOptions,
};
use dds_examples::shape_output::{self, NotAlive};
use dds_examples::shutdown;
use dds_examples::topic_types::ShapeType;
use dds_runtime::prelude::*;

const ERROR_PARSING_ARGUMENTS: u8 = 1;
const ERROR_INITIALIZING: u8 = 2;
const ERROR_RUNNING: u8 = 3;

fn main() -> ExitCode {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let prog = std::env::args()
        .next()
        .unwrap_or_else(|| "shape_main".into());
    let options = match shape_opts::parse(&args) {
        Ok(Parsed::Help) => {
            print!("{}", shape_opts::usage(&prog));
            return ExitCode::SUCCESS;
        }
        Ok(Parsed::Run { options, warnings }) => {
            for w in warnings {
                println!("{w}");
            }
            options
        }
        Err(e) => {
            println!("{e}");
            print!("{}", shape_opts::usage(&prog));
            return ExitCode::from(ERROR_PARSING_ARGUMENTS);
        }
    };
    shutdown::install();
    let app = match App::init(&options) {
        Ok(app) => app,
        Err(e) => {
            println!("failed to initialize: {e}");
            return ExitCode::from(ERROR_INITIALIZING);
        }
    };
    let result = match &app.role {
        Role::Publisher(p, writers) => run_publisher(&options, p, writers),
        Role::Subscriber(s, readers) => run_subscriber(&options, s, readers),
    };
    match result {
        Ok(()) => {
            println!("Done.");
            ExitCode::SUCCESS
        }
        Err(e) => {
            println!("run failed: {e}");
            ExitCode::from(ERROR_RUNNING)
        }
    }
}

enum Role {
    Publisher(Publisher, Vec<DataWriter<ShapeType>>),
    Subscriber(Subscriber, Vec<DataReader<ShapeType>>),
}

struct App {
    // Kept alive for the run; dropping it stops the stack's threads.
    _participant: DomainParticipant,
    role: Role,
}

/// Prints the listener lines shape_main's participant listener prints.
struct Printer {
    topic: String,
}

impl Printer {
    /// The listener of an endpoint on `topic`.
    fn for_topic(topic: &str) -> Box<Self> {
        Box::new(Printer {
            topic: topic.to_string(),
        })
    }
}

impl DataWriterListener<ShapeType> for Printer {
    fn on_publication_matched(&self, w: &DataWriter<ShapeType>, st: PublicationMatchedStatus) {
        println!(
            "{}",
            shape_output::publication_matched_line(
                &self.topic,
                w.topic().type_name(),
                st.current_count,
                st.current_count_change
            )
        );
    }
    fn on_offered_incompatible_qos(&self, w: &DataWriter<ShapeType>, st: IncompatibleQosStatus) {
        println!(
            "{}",
            shape_output::offered_incompatible_line(
                &self.topic,
                w.topic().type_name(),
                st.last_policy_id
            )
        );
    }
    fn on_offered_deadline_missed(&self, w: &DataWriter<ShapeType>, st: DeadlineMissedStatus) {
        println!(
            "{}",
            shape_output::offered_deadline_missed_line(
                &self.topic,
                w.topic().type_name(),
                st.total_count,
                st.total_count_change
            )
        );
    }
}

impl DataReaderListener<ShapeType> for Printer {
    fn on_subscription_matched(&self, r: &DataReader<ShapeType>, st: SubscriptionMatchedStatus) {
        println!(
            "{}",
            shape_output::subscription_matched_line(
                &self.topic,
                r.topic().type_name(),
                st.current_count,
                st.current_count_change
            )
        );
    }
    fn on_requested_incompatible_qos(&self, r: &DataReader<ShapeType>, st: IncompatibleQosStatus) {
        println!(
            "{}",
            shape_output::requested_incompatible_line(
                &self.topic,
                r.topic().type_name(),
                st.last_policy_id
            )
        );
    }
    fn on_requested_deadline_missed(&self, r: &DataReader<ShapeType>, st: DeadlineMissedStatus) {
        println!(
            "{}",
            shape_output::requested_deadline_missed_line(
                &self.topic,
                r.topic().type_name(),
                st.total_count,
                st.total_count_change
            )
        );
    }
}

fn topic_names(o: &ShapeOptions) -> Vec<String> {
    let base = o.topic.clone().unwrap_or_default();
    (0..o.num_topics)
        .map(|i| {
            if i == 0 {
                base.clone()
            } else {
                format!("{base}{i}")
            }
        })
        .collect()
}

fn reliability(o: &ShapeOptions) -> Reliability {
    if o.reliable {
        Reliability::RELIABLE
    } else {
        Reliability::BestEffort
    }
}

fn durability(o: &ShapeOptions) -> Durability {
    match o.durability {
        DurabilityArg::Volatile => Durability::Volatile,
        DurabilityArg::TransientLocal => Durability::TransientLocal,
        DurabilityArg::Transient => Durability::Transient,
        DurabilityArg::Persistent => Durability::Persistent,
    }
}

fn representation(o: &ShapeOptions) -> DataRepresentation {
    if o.xcdr == 2 {
        DataRepresentation::xcdr2()
    } else {
        DataRepresentation::xcdr1()
    }
}

/// `None` keeps the default history.
fn history(o: &ShapeOptions) -> Option<History> {
    match o.history_depth {
        None => None,
        Some(0) => Some(History::KeepAll),
        Some(n) => Some(History::KeepLast(n)),
    }
}

/// PRESENTATION from `--access-scope`, `--coherent` and `--ordered` (shape_main sets it on the publisher or
/// subscriber whatever the flags; INSTANCE scope by default).
fn presentation(o: &ShapeOptions) -> Presentation {
    Presentation {
        access_scope: match o.access_scope {
            None | Some(AccessScope::Instance) => PresentationAccessScope::Instance,
            Some(AccessScope::Topic) => PresentationAccessScope::Topic,
            Some(AccessScope::Group) => PresentationAccessScope::Group,
        },
        coherent_access: o.coherent,
        ordered_access: o.ordered,
    }
}

fn partition(p: &Option<String>) -> Partition {
    match p {
        Some(p) => Partition::new([p.as_str()]),
        None => Partition::default(),
    }
}

impl App {
    fn init(o: &ShapeOptions) -> DdsResult<App> {
        let mut builder = DomainParticipant::builder().domain_id(o.domain_id);
        if !o.periodic_announcement.is_zero() {
            builder = builder.spdp_interval(o.periodic_announcement);
        }
        if o.datafrag_size > 0 {
            builder = builder.fragment_size(o.datafrag_size as usize);
        }
        let participant = builder.build()?;
        let mut topics = Vec::new();
        for name in topic_names(o) {
            println!("Create topic: {name}");
            topics.push(participant.create_topic::<ShapeType>(&name, &TopicQos::default())?);
        }
        let role = if o.publish {
            publisher_role(o, &participant, &topics)?
        } else {
            subscriber_role(o, &participant, &topics)?
        };
        Ok(App {
            _participant: participant,
            role,
        })
    }
}

/// The writer QoS the options ask for.
fn writer_qos(o: &ShapeOptions) -> DataWriterQos {
    let mut qos = DataWriterQos::builder()
        .reliability(reliability(o))
        .durability(durability(o))
        .data_representation(representation(o));
    if let Some(h) = history(o) {
        // -D t / -D p: the durability service keeps what the writer keeps.
        qos = qos.history(h).durability_service(DurabilityService {
            history: h,
            ..Default::default()
        });
    }
    if let Some(s) = o.ownership_strength {
        qos = qos
            .ownership(Ownership::Exclusive)
            .ownership_strength(OwnershipStrength(s));
    }
    if !o.deadline.is_zero() {
        qos = qos.deadline(Deadline(o.deadline));
    }
    if !o.lifespan.is_zero() {
        qos = qos.lifespan(Lifespan(o.lifespan));
    }
    if o.final_instance_state == Some(FinalInstanceState::Unregister) {
        qos = qos.writer_data_lifecycle(WriterDataLifecycle {
            autodispose_unregistered_instances: false,
        });
    }
    qos.build()
}

/// The reader QoS the options ask for.
fn reader_qos(o: &ShapeOptions) -> DataReaderQos {
    let mut qos = DataReaderQos::builder()
        .reliability(reliability(o))
        .durability(durability(o))
        .data_representation(representation(o));
    if let Some(h) = history(o) {
        qos = qos.history(h);
    }
    if o.ownership_strength.is_some() {
        qos = qos.ownership(Ownership::Exclusive);
    }
    if !o.deadline.is_zero() {
        qos = qos.deadline(Deadline(o.deadline));
    }
    if !o.time_filter.is_zero() {
        qos = qos.time_based_filter(TimeBasedFilter {
            minimum_separation: o.time_filter,
        });
    }
    qos.build()
}

/// A publisher with a writer per topic, each printing its statuses.
fn publisher_role(
    o: &ShapeOptions,
    participant: &DomainParticipant,
    topics: &[Topic<ShapeType>],
) -> DdsResult<Role> {
    let publisher = participant.create_publisher(
        &PublisherQos::builder()
            .partition(partition(&o.partition))
            .presentation(presentation(o))
            .build(),
    )?;
    let qos = writer_qos(o);
    let mut writers = Vec::new();
    for t in topics {
        println!(
            "Create writer for topic: {} color: {}",
            t.name(),
            o.color.as_deref().unwrap_or("BLUE")
        );
        // Created with its listener, so that a match made inside the call is printed too.
        writers.push(publisher.create_datawriter_with_listener(
            t,
            &qos,
            Printer::for_topic(t.name()),
            StatusMask::all(),
        )?);
    }
    Ok(Role::Publisher(publisher, writers))
}

/// A subscriber with a reader per topic (of its content-filtered topic when the options filter), each
/// printing its statuses.
fn subscriber_role(
    o: &ShapeOptions,
    participant: &DomainParticipant,
    topics: &[Topic<ShapeType>],
) -> DdsResult<Role> {
    let subscriber = participant.create_subscriber(
        &SubscriberQos::builder()
            .partition(partition(&o.partition))
            .presentation(presentation(o))
            .build(),
    )?;
    let qos = reader_qos(o);
    // shape_main reads a content-filtered topic "<topic>_filtered": `--cft EXPR`, else `color = %0`
    // when -c is given.
    let filter = match (&o.cft_expression, &o.color) {
        (Some(e), _) => Some((e.as_str(), Vec::new())),
        (None, Some(c)) => Some(("color = %0", vec![c.clone()])),
        (None, None) => None,
    };
    let mut readers = Vec::new();
    for t in topics {
        let printer = Printer::for_topic(t.name());
        let r = match &filter {
            Some((expr, params)) => {
                let name = format!("{}_filtered", t.name());
                println!("Create reader for topic: {name}");
                let cft = participant.create_content_filtered_topic(&name, t, expr, params)?;
                subscriber.create_datareader_with_listener(
                    &cft,
                    &qos,
                    printer,
                    StatusMask::all(),
                )?
            }
            None => {
                println!("Create reader for topic: {}", t.name());
                subscriber.create_datareader_with_listener(t, &qos, printer, StatusMask::all())?
            }
        };
        readers.push(r);
    }
    Ok(Role::Subscriber(subscriber, readers))
}

/// A small xorshift generator seeded from the clock and pid: positions only need to differ per run.
fn seed_rng() -> impl FnMut() -> u32 {
    let nanos = std::time::SystemTime::now()
        .duration_since(std::time::UNIX_EPOCH)
        .map(|d| d.as_nanos())
        .unwrap_or(1);
    let mut state = (nanos as u64) ^ (u64::from(std::process::id()) << 32) | 1;
    move || {
        state ^= state << 13;
        state ^= state >> 7;
        state ^= state << 17;
        (state >> 16) as u32
    }
}

fn instance_colors(o: &ShapeOptions) -> Vec<String> {
    let base = o.color.clone().unwrap_or_else(|| "BLUE".into());
    (0..o.num_instances)
        .map(|j| {
            if j == 0 {
                base.clone()
            } else {
                format!("{base}{j}")
            }
        })
        .collect()
}

/// Whether iteration `n` starts (`Some(true)`) or ends (`Some(false)`) a coherent set, as shape_main does
/// with `--coherent-sample-count` (only with coherent or ordered access).
fn coherent_step(o: &ShapeOptions, n: u32, start: bool) -> bool {
    let count = o.coherent_sample_count;
    (o.coherent || o.ordered)
        && count != 0
        && if start {
            n.is_multiple_of(count)
        } else {
            n % count == count - 1
        }
}

fn run_publisher(
    o: &ShapeOptions,
    publisher: &Publisher,
    writers: &[DataWriter<ShapeType>],
) -> DdsResult<()> {
    let mut rng = seed_rng();
    let mut shape = ShapeType {
        color: o.color.clone().unwrap_or_else(|| "BLUE".into()),
        x: (rng() % WORLD_WIDTH as u32) as i32,
        y: (rng() % WORLD_HEIGHT as u32) as i32,
        shapesize: o.shapesize,
        additional_payload_size: vec![255; o.additional_payload_size as usize],
    };
    // Velocities 1..=5 in either direction, like shape_main.
    let mut velocity = || (1 + (rng() % 5) as i32) * if rng() % 2 == 1 { -1 } else { 1 };
    let mut mover = Motion {
        dx: velocity(),
        dy: velocity(),
    };
    let colors = instance_colors(o);
    let mut n = 0u32;
    while !shutdown::requested() {
        mover.step(&mut shape);
        if o.shapesize == 0 {
            shape.shapesize = if o.size_modulo > 0 {
                shape.shapesize % o.size_modulo + 1
            } else {
                shape.shapesize + 1
            };
        }
        if coherent_step(o, n, true) {
            println!("Started Coherent Set");
            publisher.begin_coherent_changes()?;
        }
        for w in writers {
            for c in &colors {
                shape.color.clone_from(c);
                match w.write(&shape) {
                    Ok(()) | Err(DdsError::Timeout) => {}
                    Err(e) => println!("write failed: {e}"),
                }
                if o.print_writer_samples {
                    println!(
                        "{}",
                        shape_output::sample_line(
                            w.topic().name(),
                            &shape.color,
                            shape.x,
                            shape.y,
                            shape.shapesize,
                            &shape.additional_payload_size
                        )
                    );
                }
            }
        }
        if coherent_step(o, n, false) {
            println!("Finished Coherent Set");
            publisher.end_coherent_changes()?;
        }
        shutdown::sleep(o.write_period);
        n += 1;
        if o.num_iterations != 0 && n >= o.num_iterations {
            break;
        }
    }
    for w in writers {
        for c in &colors {
            shape.color.clone_from(c);
            match o.final_instance_state {
                Some(FinalInstanceState::Unregister) => w.unregister_instance(&shape)?,
                Some(FinalInstanceState::Dispose) => w.dispose(&shape)?,
                None => {}
            }
        }
    }
    // Let the readers see the last updates before the process goes away.
    for w in writers {
        let _ = w.wait_for_acknowledgments(Duration::from_secs(1));
    }
    Ok(())
}

/// Ordered access with GROUP scope: the subscriber orders samples across its readers.
fn group_ordered(o: &ShapeOptions) -> bool {
    o.ordered && presentation(o).access_scope == PresentationAccessScope::Group
}

/// Reads in the subscriber's order: `get_datareaders` lists a reader once per sample, and each turn reads
/// that reader's next sample.
fn read_in_group_order(
    o: &ShapeOptions,
    subscriber: &Subscriber,
    readers: &[DataReader<ShapeType>],
    colors: &mut HashMap<(usize, InstanceHandle), String>,
) -> DdsResult<()> {
    let order = subscriber.get_datareaders(
        SampleStateMask::NOT_READ,
        ViewStateMask::ANY,
        InstanceStateMask::ANY,
    )?;
    for h in order {
        let Some((i, r)) = readers
            .iter()
            .enumerate()
            .find(|(_, r)| r.instance_handle() == h)
        else {
            continue;
        };
        let next = r
            .select()
            .sample_state(SampleStateMask::NOT_READ)
            .max_samples(1);
        let samples = if o.use_read {
            next.read()?
        } else {
            next.take()?
        };
        print_samples(o, (i, r), &samples, colors);
    }
    Ok(())
}

/// Reads the readers one after the other (by instance with `--take-read-next-instance`).
fn read_each_reader(
    o: &ShapeOptions,
    readers: &[DataReader<ShapeType>],
    colors: &mut HashMap<(usize, InstanceHandle), String>,
) -> DdsResult<()> {
    for (i, r) in readers.iter().enumerate() {
        let mut previous = InstanceHandle::NIL;
        loop {
            let samples = match (o.use_read, o.take_read_next_instance) {
                (false, true) => r.take_next_instance(previous)?,
                (true, true) => r.read_next_instance(previous)?,
                (false, false) => r.take()?,
                (true, false) => r.read()?,
            };
            let Some(first) = samples.first() else { break };
            previous = first.info.instance_handle;
            print_samples(o, (i, r), &samples, colors);
            if !o.take_read_next_instance {
                break;
            }
        }
    }
    Ok(())
}

/// Prints what one read or take of reader `i` returned: a line per sample with data, and a line per
/// instance state change.
fn print_samples(
    o: &ShapeOptions,
    (i, r): (usize, &DataReader<ShapeType>),
    samples: &[Sample<ShapeType>],
    colors: &mut HashMap<(usize, InstanceHandle), String>,
) {
    let topic = r.topic().name();
    for s in samples {
        let handle = s.info.instance_handle;
        if let Some(d) = &s.data {
            colors.insert((i, handle), d.color.clone());
            if o.color.as_ref().is_none_or(|c| *c == d.color) {
                println!(
                    "{}",
                    shape_output::sample_line(
                        topic,
                        &d.color,
                        d.x,
                        d.y,
                        d.shapesize,
                        &d.additional_payload_size
                    )
                );
            }
        }
        let state = match s.info.instance_state {
            InstanceState::Alive => continue,
            InstanceState::NotAliveDisposed => NotAlive::Disposed,
            InstanceState::NotAliveNoWriters => NotAlive::NoWriters,
        };
        let color = colors.get(&(i, handle)).cloned().unwrap_or_default();
        if o.color.as_ref().is_none_or(|c| *c == color) {
            println!(
                "{}",
                shape_output::instance_state_line(topic, &color, state)
            );
        }
    }
}

fn run_subscriber(
    o: &ShapeOptions,
    subscriber: &Subscriber,
    readers: &[DataReader<ShapeType>],
) -> DdsResult<()> {
    // Key of each instance seen with data, to name instances in NOT_ALIVE lines.
    let mut colors: HashMap<(usize, InstanceHandle), String> = HashMap::new();
    let mut n = 0u32;
    while !shutdown::requested() {
        if o.coherent {
            println!("Reading coherent sets, iteration {n}");
        }
        if o.ordered {
            println!("Reading with ordered access, iteration {n}");
        }
        let access = o.coherent || o.ordered;
        if access {
            subscriber.begin_access()?;
        }
        if group_ordered(o) {
            read_in_group_order(o, subscriber, readers, &mut colors)?;
        } else {
            read_each_reader(o, readers, &mut colors)?;
        }
        if access {
            subscriber.end_access()?;
        }
        n += 1;
        if o.num_iterations != 0 && n >= o.num_iterations {
            break;
        }
        shutdown::sleep(o.read_period);
    }
    Ok(())
}
