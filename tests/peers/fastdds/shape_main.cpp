// A Fast DDS 2.9 peer with the command-line and output contract of the OMG interoperability suite's
// shape_main (omg-dds/dds-rtps srcCxx/shape_main.cxx): the subset of options our interop tests use.
// Options it does not implement print a line containing "not supported" and exit 2.
//
// Build: scripts/build-fastdds-peer.sh  ->  target/peers/fastdds_shape_main

#include <getopt.h>
#include <signal.h>
#include <unistd.h>

#include <atomic>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <map>
#include <random>
#include <string>
#include <thread>
#include <vector>

#include <fastdds/dds/domain/DomainParticipant.hpp>
#include <fastdds/dds/domain/DomainParticipantFactory.hpp>
#include <fastdds/dds/domain/DomainParticipantListener.hpp>
#include <fastdds/dds/publisher/DataWriter.hpp>
#include <fastdds/dds/publisher/Publisher.hpp>
#include <fastdds/dds/subscriber/DataReader.hpp>
#include <fastdds/dds/subscriber/SampleInfo.hpp>
#include <fastdds/dds/subscriber/Subscriber.hpp>
#include <fastdds/dds/subscriber/qos/DataReaderQos.hpp>
#include <fastdds/dds/topic/TypeSupport.hpp>

#include "shape_type.hpp"

using namespace eprosima::fastdds::dds;
using eprosima::fastrtps::rtps::InstanceHandle_t;

namespace {

std::atomic<bool> all_done{false};

void on_signal(int) { all_done = true; }

struct Options {
    int domain = 0;
    bool publish = false;
    bool subscribe = false;
    bool reliable = true;
    int depth = -1;
    int deadline_ms = 0;
    int strength = -1;
    std::string topic;
    std::string color;
    std::string partition;
    char durability = 'v';
    int xcdr = 1;
    bool print_writer = false;
    int shapesize = 20;
    bool use_read = false;
    int write_period_ms = 33;
    int read_period_ms = 100;
    int time_filter_ms = 0;
    int lifespan_ms = 0;
    unsigned num_iterations = 0;
    unsigned num_instances = 1;
    unsigned num_topics = 1;
    char final_state = 0;
    bool coherent = false;
    bool ordered = false;
    bool access_scope_set = false;
    char access_scope = 'i';
    unsigned additional_payload_size = 0;
    bool take_read = false;
    int size_modulo = 0;
    bool cft = false;
};

const char* policy_name(QosPolicyId_t id) {
    switch (id) {
        case USERDATA_QOS_POLICY_ID: return "USERDATA";
        case DURABILITY_QOS_POLICY_ID: return "DURABILITY";
        case PRESENTATION_QOS_POLICY_ID: return "PRESENTATION";
        case DEADLINE_QOS_POLICY_ID: return "DEADLINE";
        case LATENCYBUDGET_QOS_POLICY_ID: return "LATENCYBUDGET";
        case OWNERSHIP_QOS_POLICY_ID: return "OWNERSHIP";
        case OWNERSHIPSTRENGTH_QOS_POLICY_ID: return "OWNERSHIPSTRENGTH";
        case LIVELINESS_QOS_POLICY_ID: return "LIVELINESS";
        case TIMEBASEDFILTER_QOS_POLICY_ID: return "TIMEBASEDFILTER";
        case PARTITION_QOS_POLICY_ID: return "PARTITION";
        case RELIABILITY_QOS_POLICY_ID: return "RELIABILITY";
        case DESTINATIONORDER_QOS_POLICY_ID: return "DESTINATIONORDER";
        case HISTORY_QOS_POLICY_ID: return "HISTORY";
        case RESOURCELIMITS_QOS_POLICY_ID: return "RESOURCELIMITS";
        case ENTITYFACTORY_QOS_POLICY_ID: return "ENTITYFACTORY";
        case WRITERDATALIFECYCLE_QOS_POLICY_ID: return "WRITERDATALIFECYCLE";
        case READERDATALIFECYCLE_QOS_POLICY_ID: return "READERDATALIFECYCLE";
        case TOPICDATA_QOS_POLICY_ID: return "TOPICDATA";
        case GROUPDATA_QOS_POLICY_ID: return "GROUPDATA";
        case TRANSPORTPRIORITY_QOS_POLICY_ID: return "TRANSPORTPRIORITY";
        case LIFESPAN_QOS_POLICY_ID: return "LIFESPAN";
        case DURABILITYSERVICE_QOS_POLICY_ID: return "DURABILITYSERVICE";
        case DATAREPRESENTATION_QOS_POLICY_ID: return "DATAREPRESENTATION";
        default: return "Unknown";
    }
}

class StatusPrinter : public DomainParticipantListener {
public:
    void on_publication_matched(DataWriter* dw, const PublicationMatchedStatus& st) override {
        std::printf("on_publication_matched() topic: '%s'  type: '%s' : matched readers %d (change = %d)\n",
                    dw->get_topic()->get_name().c_str(), dw->get_topic()->get_type_name().c_str(),
                    st.current_count, st.current_count_change);
        std::fflush(stdout);
    }
    void on_subscription_matched(DataReader* dr, const SubscriptionMatchedStatus& st) override {
        std::printf("on_subscription_matched() topic: '%s'  type: '%s' : matched writers %d (change = %d)\n",
                    dr->get_topicdescription()->get_name().c_str(),
                    dr->get_topicdescription()->get_type_name().c_str(), st.current_count,
                    st.current_count_change);
        std::fflush(stdout);
    }
    void on_offered_incompatible_qos(DataWriter* dw, const OfferedIncompatibleQosStatus& st) override {
        std::printf("on_offered_incompatible_qos() topic: '%s'  type: '%s' : %d (%s)\n",
                    dw->get_topic()->get_name().c_str(), dw->get_topic()->get_type_name().c_str(),
                    st.last_policy_id, policy_name(st.last_policy_id));
        std::fflush(stdout);
    }
    void on_requested_incompatible_qos(DataReader* dr, const RequestedIncompatibleQosStatus& st) override {
        std::printf("on_requested_incompatible_qos() topic: '%s'  type: '%s' : %d (%s)\n",
                    dr->get_topicdescription()->get_name().c_str(),
                    dr->get_topicdescription()->get_type_name().c_str(), st.last_policy_id,
                    policy_name(st.last_policy_id));
        std::fflush(stdout);
    }
};

void usage(const char* prog) {
    std::printf("%s: -P|-S -t TOPIC [-d DOMAIN] [-b|-r] [-k DEPTH] [-D v|l|t|p] [-x 1|2] [-p PARTITION]\n"
                "  [-c COLOR] [-w] [-z SIZE] [-s STRENGTH] [-f DEADLINE_MS] [-R] [--write-period MS]\n"
                "  [--read-period MS] [--num-iterations N] [--num-instances N] [--final-instance-state u|d]\n"
                "  [--additional-payload-size BYTES] [--take-read] [--lifespan MS] [--size-modulo N]\n",
                prog);
}

bool parse(int argc, char** argv, Options& o) {
    static const struct option longs[] = {
        {"help", no_argument, nullptr, 'h'},
        {"write-period", required_argument, nullptr, 'W'},
        {"read-period", required_argument, nullptr, 'A'},
        {"final-instance-state", required_argument, nullptr, 'M'},
        {"access-scope", required_argument, nullptr, 'C'},
        {"coherent", no_argument, nullptr, 'T'},
        {"ordered", no_argument, nullptr, 'O'},
        {"coherent-sample-count", required_argument, nullptr, 'H'},
        {"additional-payload-size", required_argument, nullptr, 'B'},
        {"num-topics", required_argument, nullptr, 'E'},
        {"lifespan", required_argument, nullptr, 'l'},
        {"num-instances", required_argument, nullptr, 'I'},
        {"num-iterations", required_argument, nullptr, 'n'},
        {"take-read", no_argument, nullptr, 'K'},
        {"time-filter", required_argument, nullptr, 'i'},
        {"periodic-announcement", required_argument, nullptr, 'N'},
        {"datafrag-size", required_argument, nullptr, 'Z'},
        {"cft", required_argument, nullptr, 'F'},
        {"size-modulo", required_argument, nullptr, 'Q'},
        {nullptr, 0, nullptr, 0}};
    int opt;
    bool ok = true;
    while ((opt = getopt_long(argc, argv, "hPSbrRwc:d:D:f:k:p:s:x:t:v:z:", longs, nullptr)) != -1) {
        switch (opt) {
            case 'h': usage(argv[0]); std::exit(0);
            case 'v': break;
            case 'P': o.publish = true; break;
            case 'S': o.subscribe = true; break;
            case 'b': o.reliable = false; break;
            case 'r': o.reliable = true; break;
            case 'R': o.use_read = true; break;
            case 'w': o.print_writer = true; break;
            case 'c': o.color = optarg; break;
            case 'd': o.domain = std::atoi(optarg); break;
            case 'D': o.durability = optarg[0]; break;
            case 'f': o.deadline_ms = std::atoi(optarg); break;
            case 'k': o.depth = std::atoi(optarg); break;
            case 'p': o.partition = optarg; break;
            case 's': o.strength = std::atoi(optarg); break;
            case 'x': o.xcdr = optarg[0] == '2' ? 2 : 1; ok = ok && (optarg[0] == '1' || optarg[0] == '2'); break;
            case 't': o.topic = optarg; break;
            case 'z': o.shapesize = std::atoi(optarg); break;
            case 'W': o.write_period_ms = std::atoi(optarg); break;
            case 'A': o.read_period_ms = std::atoi(optarg); break;
            case 'M': o.final_state = optarg[0]; ok = ok && (optarg[0] == 'u' || optarg[0] == 'd'); break;
            case 'C': o.access_scope_set = true; o.access_scope = optarg[0]; break;
            case 'T': o.coherent = true; break;
            case 'O': o.ordered = true; break;
            case 'H': break;
            case 'B': o.additional_payload_size = static_cast<unsigned>(std::atoi(optarg)); break;
            case 'E': o.num_topics = static_cast<unsigned>(std::atoi(optarg)); break;
            case 'l': o.lifespan_ms = std::atoi(optarg); break;
            case 'I': o.num_instances = static_cast<unsigned>(std::atoi(optarg)); break;
            case 'n': o.num_iterations = static_cast<unsigned>(std::atoi(optarg)); break;
            case 'K': o.take_read = true; break;
            case 'i': o.time_filter_ms = std::atoi(optarg); break;
            case 'N': break;
            case 'Z': break;
            case 'F': o.cft = true; break;
            case 'Q': o.size_modulo = std::atoi(optarg); break;
            default: ok = false; break;
        }
    }
    if (o.topic.empty()) {
        std::printf("please specify topic name [-t]\n");
        ok = false;
    }
    if (o.publish == o.subscribe) {
        std::printf("please specify publish [-P] or subscribe [-S]\n");
        ok = false;
    }
    if (o.durability != 'v' && o.durability != 'l' && o.durability != 't' && o.durability != 'p') ok = false;
    if (o.num_instances < 1) ok = false;
    if (ok && o.publish && o.color.empty()) {
        o.color = "BLUE";
        std::printf("warning: color was not specified, defaulting to \"BLUE\"\n");
    }
    if (!ok) usage(argv[0]);
    return ok;
}

bool reject_unsupported(const Options& o) {
    std::vector<const char*> bad;
    if (o.coherent) bad.push_back("Presentation Coherent Access");
    if (o.ordered) bad.push_back("Presentation Ordered Access");
    if (o.access_scope_set && o.access_scope != 'i') bad.push_back("Presentation Access Scope");
    if (o.time_filter_ms > 0) bad.push_back("TimeBasedFilter");
    if (o.num_topics != 1) bad.push_back("--num-topics");
    if (o.cft) bad.push_back("ContentFilteredTopic expression");
    for (const char* b : bad) std::printf("    %s = not supported\n", b);
    return !bad.empty();
}

DurabilityQosPolicyKind durability_kind(char d) {
    switch (d) {
        case 'l': return TRANSIENT_LOCAL_DURABILITY_QOS;
        case 't': return TRANSIENT_DURABILITY_QOS;
        case 'p': return PERSISTENT_DURABILITY_QOS;
        default: return VOLATILE_DURABILITY_QOS;
    }
}

DataRepresentationQosPolicy& representation(DataWriterQos& q) { return q.representation(); }
DataRepresentationQosPolicy& representation(DataReaderQos& q) { return q.type_consistency().representation; }

template <typename Q>
void common_qos(const Options& o, Q& q) {
    q.reliability().kind = o.reliable ? RELIABLE_RELIABILITY_QOS : BEST_EFFORT_RELIABILITY_QOS;
    q.durability().kind = durability_kind(o.durability);
    representation(q).m_value.clear();
    representation(q).m_value.push_back(o.xcdr == 2 ? XCDR2_DATA_REPRESENTATION : XCDR_DATA_REPRESENTATION);
    if (o.depth > 0) {
        q.history().kind = KEEP_LAST_HISTORY_QOS;
        q.history().depth = o.depth;
    } else if (o.depth == 0) {
        q.history().kind = KEEP_ALL_HISTORY_QOS;
    }
    if (o.deadline_ms > 0) q.deadline().period = eprosima::fastrtps::Duration_t(o.deadline_ms * 1e-3);
    q.ownership().kind = o.strength != -1 ? EXCLUSIVE_OWNERSHIP_QOS : SHARED_OWNERSHIP_QOS;
}

void print_shape(const std::string& topic, const ShapeType& s) {
    std::printf("%-10s %-10s %03d %03d [%d]", topic.c_str(), s.color.c_str(), s.x, s.y, s.shapesize);
    if (!s.additional_payload_size.empty()) std::printf(" {%u}", s.additional_payload_size.back());
    std::printf("\n");
}

int run_publisher(const Options& o, DomainParticipant* dp, Topic* topic) {
    PublisherQos pq = PUBLISHER_QOS_DEFAULT;
    if (!o.partition.empty()) pq.partition().push_back(o.partition.c_str());
    Publisher* pub = dp->create_publisher(pq, nullptr, StatusMask::none());
    if (pub == nullptr) return 2;
    DataWriterQos wq = DATAWRITER_QOS_DEFAULT;
    common_qos(o, wq);
    if (o.strength != -1) wq.ownership_strength().value = static_cast<uint32_t>(o.strength);
    if (o.lifespan_ms > 0) wq.lifespan().duration = eprosima::fastrtps::Duration_t(o.lifespan_ms * 1e-3);
    if (o.final_state == 'u') wq.writer_data_lifecycle().autodispose_unregistered_instances = false;
    if (o.xcdr == 2)
        // Fast DDS 2.9 leaves the representation out of its SEDP announcement: peers see XCDR1 offered
        // while the payloads carry D_CDR2 (this type support writes what -x asks for).
        std::printf("warning: Fast DDS 2.9 writers announce XCDR1 only; -x 2 affects encoding only\n");
    std::printf("Create writer for topic: %s color: %s\n", o.topic.c_str(), o.color.c_str());
    DataWriter* dw = pub->create_datawriter(topic, wq, nullptr, StatusMask::none());
    if (dw == nullptr) {
        std::printf("failed to create datawriter\n");
        return 2;
    }
    const int width = 240, height = 270;
    std::mt19937 rng(static_cast<unsigned>(std::time(nullptr)) ^ static_cast<unsigned>(getpid()));
    ShapeType shape;
    shape.color = o.color;
    shape.shapesize = o.shapesize;
    shape.x = static_cast<int32_t>(rng() % width);
    shape.y = static_cast<int32_t>(rng() % height);
    int xvel = static_cast<int>(rng() % 5 + 1) * ((rng() % 2) ? -1 : 1);
    int yvel = static_cast<int>(rng() % 5 + 1) * ((rng() % 2) ? -1 : 1);
    shape.additional_payload_size.assign(o.additional_payload_size, 255);
    unsigned n = 0;
    while (!all_done) {
        shape.x += xvel;
        shape.y += yvel;
        if (shape.x < 0) { shape.x = 0; xvel = -xvel; }
        if (shape.x > width) { shape.x = width; xvel = -xvel; }
        if (shape.y < 0) { shape.y = 0; yvel = -yvel; }
        if (shape.y > height) { shape.y = height; yvel = -yvel; }
        if (o.shapesize == 0)
            shape.shapesize = o.size_modulo > 0 ? (shape.shapesize % o.size_modulo) + 1 : shape.shapesize + 1;
        for (unsigned j = 0; j < o.num_instances; ++j) {
            shape.color = o.color + (j > 0 ? std::to_string(j) : "");
            dw->write(&shape, HANDLE_NIL);
            if (o.print_writer) print_shape(o.topic, shape);
        }
        std::fflush(stdout);
        std::this_thread::sleep_for(std::chrono::milliseconds(o.write_period_ms));
        ++n;
        if (o.num_iterations != 0 && n >= o.num_iterations) break;
    }
    for (unsigned j = 0; j < o.num_instances; ++j) {
        shape.color = o.color + (j > 0 ? std::to_string(j) : "");
        if (o.final_state == 'u') dw->unregister_instance(&shape, HANDLE_NIL);
        if (o.final_state == 'd') dw->dispose(&shape, HANDLE_NIL);
    }
    dw->wait_for_acknowledgments(eprosima::fastrtps::Duration_t(1, 0));
    return 0;
}

int run_subscriber(const Options& o, DomainParticipant* dp, Topic* topic) {
    SubscriberQos sq = SUBSCRIBER_QOS_DEFAULT;
    if (!o.partition.empty()) sq.partition().push_back(o.partition.c_str());
    Subscriber* sub = dp->create_subscriber(sq, nullptr, StatusMask::none());
    if (sub == nullptr) return 2;
    DataReaderQos rq = DATAREADER_QOS_DEFAULT;
    common_qos(o, rq);
    if (o.xcdr == 2)
        // Fast DDS 2.9 keeps a reader's representation out of its SEDP announcement (its RTPS ReaderQos
        // has no such field), so remote writers see the default, XCDR1. Both encodings are decoded.
        std::printf("warning: Fast DDS 2.9 readers announce XCDR1 only; -x 2 affects decoding only\n");
    // shape_main reads through a content-filtered topic "<topic>_filtered" when -c is given; this peer
    // filters on the color in the application, which gives the same printed output.
    std::printf("Create reader for topic: %s\n", (o.color.empty() ? o.topic : o.topic + "_filtered").c_str());
    DataReader* dr = sub->create_datareader(topic, rq, nullptr, StatusMask::none());
    if (dr == nullptr) {
        std::printf("failed to create datareader\n");
        return 2;
    }
    std::map<InstanceHandle_t, std::string> instance_color;
    unsigned n = 0;
    while (!all_done) {
        InstanceHandle_t previous = HANDLE_NIL;
        for (;;) {
            FASTDDS_CONST_SEQUENCE(DataSeq, ShapeType);
            DataSeq samples;
            SampleInfoSeq infos;
            ReturnCode_t rc;
            if (o.take_read)
                rc = o.use_read ? dr->read(samples, infos) : dr->take(samples, infos);
            else
                rc = o.use_read ? dr->read_next_instance(samples, infos, LENGTH_UNLIMITED, previous)
                                : dr->take_next_instance(samples, infos, LENGTH_UNLIMITED, previous);
            if (rc != ReturnCode_t::RETCODE_OK) break;
            for (LoanableCollection::size_type i = 0; i < samples.length(); ++i) {
                const SampleInfo& info = infos[i];
                if (std::getenv("SHAPE_DEBUG") != nullptr) {
                    std::fprintf(stderr, "sample valid=%d state=%d handle=", info.valid_data ? 1 : 0,
                                 static_cast<int>(info.instance_state));
                    for (int b = 0; b < 16; ++b) std::fprintf(stderr, "%02x", info.instance_handle.value[b]);
                    std::fprintf(stderr, "\n");
                }
                if (info.valid_data) {
                    instance_color[info.instance_handle] = samples[i].color;
                    if (o.color.empty() || samples[i].color == o.color) print_shape(o.topic, samples[i]);
                }
                if (info.instance_state != ALIVE_INSTANCE_STATE) {
                    auto it = instance_color.find(info.instance_handle);
                    const std::string color = it == instance_color.end() ? std::string() : it->second;
                    if (!o.color.empty() && color != o.color) continue;
                    if (info.instance_state == NOT_ALIVE_NO_WRITERS_INSTANCE_STATE)
                        std::printf("%-10s %-10s NOT_ALIVE_NO_WRITERS_INSTANCE_STATE\n", o.topic.c_str(), color.c_str());
                    else if (info.instance_state == NOT_ALIVE_DISPOSED_INSTANCE_STATE)
                        std::printf("%-10s %-10s NOT_ALIVE_DISPOSED_INSTANCE_STATE\n", o.topic.c_str(), color.c_str());
                }
            }
            if (infos.length() > 0) previous = infos[0].instance_handle;
            dr->return_loan(samples, infos);
            if (o.take_read) break;
        }
        std::fflush(stdout);
        ++n;
        if (o.num_iterations != 0 && n >= o.num_iterations) break;
        std::this_thread::sleep_for(std::chrono::milliseconds(o.read_period_ms));
    }
    return 0;
}

}  // namespace

int main(int argc, char** argv) {
    setvbuf(stdout, nullptr, _IOLBF, 0);
    signal(SIGINT, on_signal);
    signal(SIGTERM, on_signal);
    Options o;
    if (!parse(argc, argv, o)) return 1;
    if (reject_unsupported(o)) return 2;

    DomainParticipantQos pq = PARTICIPANT_QOS_DEFAULT;
    pq.properties().properties().emplace_back("fastdds.type_propagation", "disabled");
    StatusPrinter printer;
    DomainParticipant* dp = DomainParticipantFactory::get_instance()->create_participant(
        static_cast<DomainId_t>(o.domain), pq, &printer, StatusMask::all());
    if (dp == nullptr) {
        std::printf("failed to create participant\n");
        return 2;
    }
    TypeSupport type(new ShapeTypeSupport(o.xcdr == 2));
    type.register_type(dp, "ShapeType");
    std::printf("Create topic: %s\n", o.topic.c_str());
    Topic* topic = dp->create_topic(o.topic, "ShapeType", TOPIC_QOS_DEFAULT);
    if (topic == nullptr) {
        std::printf("failed to create topic\n");
        return 2;
    }
    const int rc = o.publish ? run_publisher(o, dp, topic) : run_subscriber(o, dp, topic);
    dp->delete_contained_entities();
    DomainParticipantFactory::get_instance()->delete_participant(dp);
    if (rc == 0) std::printf("Done.\n");
    return rc;
}
