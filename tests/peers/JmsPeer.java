// A JMS peer as AsapRealizer's ActiveMQ adapters are (OpenWire, javax.jms): it publishes a BML
// block as a TextMessage on the topic asap.bml.request and expects the realizer's feedback on
// asap.bml.feedback as TextMessages, the block's start and end among them, within 10 s.
// tests/activemq.rs runs it in Java's source-file mode against Debian's activemq.
//
// Usage: java -cp ACTIVEMQ_JARS JmsPeer.java tcp://127.0.0.1:PORT BLOCK_ID
// Prints "ok ..." / "FAILED ..." lines and exits 1 if any failed.

import javax.jms.Connection;
import javax.jms.Message;
import javax.jms.MessageConsumer;
import javax.jms.MessageProducer;
import javax.jms.Session;
import javax.jms.TextMessage;
import javax.jms.Topic;
import org.apache.activemq.ActiveMQConnectionFactory;

public class JmsPeer {
    public static void main(String[] args) throws Exception {
        String url = args[0];
        String id = args[1];
        Connection connection = new ActiveMQConnectionFactory(url).createConnection();
        connection.start();
        Session session = connection.createSession(false, Session.AUTO_ACKNOWLEDGE);
        Topic feedback = session.createTopic("asap.bml.feedback");
        MessageConsumer consumer = session.createConsumer(feedback);
        MessageProducer producer = session.createProducer(session.createTopic("asap.bml.request"));
        Thread.sleep(300);
        TextMessage bml = session.createTextMessage(
            "<bml xmlns=\"http://www.bml-initiative.org/bml/bml-1.0\" id=\"" + id + "\">"
            + "<head id=\"h\" lexeme=\"NOD\" start=\"0\" end=\"0.4\"/></bml>");
        producer.send(bml);
        boolean started = false, ended = false, allText = true;
        int count = 0;
        long until = System.currentTimeMillis() + 10_000;
        while (!ended && System.currentTimeMillis() < until) {
            Message m = consumer.receive(200);
            if (m == null) {
                continue;
            }
            count++;
            if (!(m instanceof TextMessage)) {
                allText = false;
                System.out.println("not a TextMessage: " + m.getClass().getName());
                continue;
            }
            String text = ((TextMessage) m).getText();
            started |= text.startsWith("<blockProgress") && text.contains("id=\"" + id + ":start\"");
            ended |= text.startsWith("<blockProgress") && text.contains("id=\"" + id + ":end\"");
        }
        connection.close();
        int failed = 0;
        failed += check(allText && count > 0, "the feedback arrives as TextMessage (" + count + " messages)");
        failed += check(started, "the block's start (blockProgress " + id + ":start)");
        failed += check(ended, "the block's end (blockProgress " + id + ":end) within 10 s");
        System.out.println(failed + " failed");
        System.exit(failed == 0 ? 0 : 1);
    }

    static int check(boolean ok, String what) {
        System.out.println((ok ? "ok     " : "FAILED ") + what);
        return ok ? 0 : 1;
    }
}
