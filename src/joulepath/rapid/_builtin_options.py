# ruff: noqa: E501  (a signature is one line, as in the manual)
"""RobotWare options' RAPID instructions, functions and data types, as data.

The same notation and block layout as :mod:`joulepath.rapid._builtin_table` (see
:mod:`joulepath.rapid.builtins`). Blocks marked ``partial`` hold only the parameters confirmed
(from the option's manual and from their use in published programs); a call with other optional
arguments is matched leniently there.
"""

from __future__ import annotations

from joulepath.rapid._builtin_table import STD, Block, Row

MULTITASKING = "Multitasking"
SOCKET = "Socket Messaging"
VISION = "Integrated Vision"
GRIPPER = "SmartGripper"
ARC = "Arc"
DISPENSE = "Dispense"
FORCE = "Force Control"
CONVEYOR = "Conveyor Tracking"
INDEPENDENT = "Independent Axes"
PATH_OFFSET = "Path Offset"
RMQ = "RAPID Message Queue"
WORLDZONES = "World Zones"
EGM = "Externally Guided Motion"
CSS = "Cartesian Soft Servo"

_SRC_EGM = "ABB, Application manual: Externally Guided Motion; its use in published programs"
_SRC_CSS = "ABB, Application manual: Cartesian Soft Servo; its use in published programs"
_SRC_MT = "ABB, Application manual: Multitasking; " + STD
_SRC_SOCKET = "ABB, Application manual: Controller software IRC5 (Socket Messaging); " + STD
_SRC_VISION = "ABB, Application manual: Integrated Vision; its use in published programs"
_SRC_GRIPPER = "ABB, Product manual: SmartGripper (IRB 14000); its use in published programs"
_SRC_ARC = "ABB, Application manual: Arc and Arc Sensor, RobotWare Arc; its use in published programs"
_SRC_DISPENSE = "ABB, Application manual: Dispense"
_SRC_FORCE = "ABB, Application manual: Force Control; its use in published programs"
_SRC_CONVEYOR = "ABB, Application manual: Conveyor tracking; its use in published programs"

MULTITASKING_ROWS: tuple[Row, ...] = (
    ("SyncMoveOn", r"SyncID:syncident TaskList:tasks{*} [\TimeOut:num]", "wait"),
    ("SyncMoveOff", r"SyncID:syncident [\TimeOut:num]", "wait"),
    ("SyncMoveUndo", r"", "none"),
    ("SyncMoveSuspend", r"", "none"),
    ("SyncMoveResume", r"", "none"),
    ("WaitSyncTask", r"[\InPos] SyncID:syncident TaskList:tasks{*} [\TimeOut:num]", "wait"),
)  # fmt: skip

MULTITASKING_FUNCTIONS: tuple[Row, ...] = (
    ("IsSyncMoveOn", r"", "bool runtime"),
)  # fmt: skip

SOCKET_ROWS: tuple[Row, ...] = (
    ("SocketCreate", r"Socket:socketdev& [\UDP]", "none"),
    ("SocketConnect", r"Socket:socketdev Address:string Port:num [\Time:num]", "wait"),
    ("SocketBind", r"Socket:socketdev LocalAddress:string LocalPort:num", "none"),
    ("SocketListen", r"Socket:socketdev", "none"),
    ("SocketAccept", r"Socket:socketdev ClientSocket:socketdev& [\ClientAddress:string!] [\Time:num]", "wait"),
    ("SocketSend", r"Socket:socketdev [\Str:string|\RawData:rawbytes|\Data:byte{*}] [\NoOfBytes:num]", "none"),
    ("SocketSendTo", r"Socket:socketdev RemoteAddress:string RemotePort:num [\Str:string|\RawData:rawbytes|\Data:byte{*}] [\NoOfBytes:num]", "none"),
    ("SocketReceive", r"Socket:socketdev [\Str:string!|\RawData:rawbytes!|\Data:byte{*}!] [\ReadNoOfBytes:num] [\NoRecBytes:num!] [\Time:num]", "wait"),
    ("SocketReceiveFrom", r"Socket:socketdev [\Str:string!|\RawData:rawbytes!|\Data:byte{*}!] [\NoRecBytes:num!] RemoteAddress:string! RemotePort:num! [\Time:num]", "wait"),
    ("SocketClose", r"Socket:socketdev", "none"),
)  # fmt: skip

SOCKET_FUNCTIONS: tuple[Row, ...] = (
    ("SocketGetStatus", r"Socket:socketdev", "socketstatus runtime"),
    ("SocketPeek", r"Socket:socketdev [\Time:num]", "num runtime", "partial"),
)  # fmt: skip

RMQ_ROWS: tuple[Row, ...] = (
    ("RMQFindSlot", r"Slot:rmqslot& Name:string", "none"),
    ("RMQSendMessage", r"Slot:rmqslot SendData:anytype [\UserDef:num]", "none"),
    ("RMQSendWait", r"Slot:rmqslot SendData:anytype [\UserDef:num] Message:rmqmessage! ReceiveDataType:anytype [\TimeOut:num]", "wait"),
    ("RMQGetMessage", r"Message:rmqmessage!", "none"),
    ("RMQGetMsgData", r"Message:rmqmessage Data:anytype!", "none"),
    ("RMQGetMsgHeader", r"Message:rmqmessage [\Header:rmqheader!] [\SenderId:rmqslot!] [\UserDef:num!]", "none"),
    ("RMQReadWait", r"Message:rmqmessage! [\TimeOut:num]", "wait"),
    ("RMQEmptyQueue", r"", "none"),
    ("IRMQMessage", r"InterruptDataType:anytype Interrupt:intnum", "none"),
)  # fmt: skip

VISION_ROWS: tuple[Row, ...] = (
    ("CamReqImage", r"Camera:cameradev [\SceneId:num] [\KeepOldResults] [\AwaitComplete]", "none"),
    ("CamGetResult", r"Camera:cameradev CamTarget:cameratarget! [\SceneId:num] [\MaxTime:num]", "wait"),
    ("CamSetProgramMode", r"Camera:cameradev", "none"),
    ("CamSetRunMode", r"Camera:cameradev", "none"),
    ("CamLoadJob", r"Camera:cameradev Name:string [\KeepTargets] [\MaxTime:num]", "wait"),
    ("CamStartLoadJob", r"Camera:cameradev Name:string [\KeepTargets]", "none"),
    ("CamWaitLoadJob", r"Camera:cameradev", "wait"),
    ("CamFlush", r"Camera:cameradev", "none"),
    ("CamSetExposure", r"Camera:cameradev [\ExposureTime:num] [\Brightness:num] [\Contrast:num]", "none"),
    ("CamSetParameter", r"Camera:cameradev ParName:string [\Num:num|\Bool:bool|\Str:string]", "none"),
    ("CamGetParameter", r"Camera:cameradev ParName:string [\Num:num!|\Bool:bool!|\Str:string!]", "none"),
)  # fmt: skip

VISION_FUNCTIONS: tuple[Row, ...] = (
    ("CamGetName", r"Camera:cameradev", "string"),
    ("CamGetLoadedJob", r"Camera:cameradev", "string runtime"),
    ("CamNumberOfResults", r"Camera:cameradev [\SceneId:num]", "num runtime"),
    ("CamGetExposure", r"Camera:cameradev [\ExposureTime:num!] [\Brightness:num!] [\Contrast:num!]", "num runtime"),
)  # fmt: skip

GRIPPER_ROWS: tuple[Row, ...] = (
    ("g_Init", r"[\maxSpd:num] [\holdForce:num] [\phyLimit:num] [\Calibrate] [\Grip]", "wait"),
    ("g_Calibrate", r"[\Grip] [\Jog]", "wait"),
    ("g_GripIn", r"[\holdForce:num] [\targetPos:num] [\NoWait]", "wait"),
    ("g_GripOut", r"[\holdForce:num] [\targetPos:num] [\NoWait]", "wait"),
    ("g_MoveTo", r"targetPos:num [\NoWait]", "wait"),
    ("g_JogIn", r"", "none"),
    ("g_JogOut", r"", "none"),
    ("g_Stop", r"", "none"),
    ("g_SetForce", r"", "none"),
    ("g_SetMaxSpd", r"", "none"),
    ("g_BlowOn1", r"", "io"),
    ("g_BlowOff1", r"", "io"),
    ("g_BlowOn2", r"", "io"),
    ("g_BlowOff2", r"", "io"),
    ("g_VacuumOn1", r"", "io"),
    ("g_VacuumOff1", r"", "io"),
    ("g_VacuumOn2", r"", "io"),
    ("g_VacuumOff2", r"", "io"),
)  # fmt: skip

GRIPPER_FUNCTIONS: tuple[Row, ...] = (
    ("g_GetPos", r"", "num runtime"),
    ("g_GetState", r"", "num runtime"),
    ("g_IsCalibrated", r"", "bool runtime"),
    ("g_GetPressure1", r"", "num runtime"),
    ("g_GetPressure2", r"", "num runtime"),
)  # fmt: skip

_ARC_TAIL = r"[\Weave:weavedata] Zone:zonedata [\Inpos:stoppointdata] Tool:tooldata [\WObj:wobjdata] [\Corr] [\Track:trackdata] [\SeamName:string] [\TLoad:loaddata]"
ARC_ROWS: tuple[Row, ...] = (
    ("ArcL", rf"[\On|\Off] ToPoint:robtarget [\ID:identno] Speed:speeddata [\T:num] Seam:seamdata Weld:welddata {_ARC_TAIL}", "move linear process"),
    ("ArcLStart", rf"ToPoint:robtarget [\ID:identno] Speed:speeddata [\T:num] Seam:seamdata Weld:welddata {_ARC_TAIL}", "move linear process"),
    ("ArcLEnd", rf"ToPoint:robtarget [\ID:identno] Speed:speeddata [\T:num] Seam:seamdata Weld:welddata {_ARC_TAIL}", "move linear process"),
    ("ArcC", rf"[\On|\Off] CirPoint:robtarget ToPoint:robtarget [\ID:identno] Speed:speeddata [\T:num] Seam:seamdata Weld:welddata {_ARC_TAIL}", "move circular process"),
    ("ArcCStart", rf"CirPoint:robtarget ToPoint:robtarget [\ID:identno] Speed:speeddata [\T:num] Seam:seamdata Weld:welddata {_ARC_TAIL}", "move circular process"),
    ("ArcCEnd", rf"CirPoint:robtarget ToPoint:robtarget [\ID:identno] Speed:speeddata [\T:num] Seam:seamdata Weld:welddata {_ARC_TAIL}", "move circular process"),
    ("ArcMoveAbsJ", r"[\Conc] ToJointPos:jointtarget [\ID:identno] [\NoEOffs] Speed:speeddata [\T:num] Zone:zonedata [\Inpos:stoppointdata] Tool:tooldata [\WObj:wobjdata] [\TLoad:loaddata]", "move absjoint"),
    ("ArcMoveExtJ", r"ToJointPos:jointtarget Speed:speeddata Zone:zonedata", "move external"),
    ("ArcRefresh", r"", "none"),
    ("ArcKill", r"", "none"),
)  # fmt: skip

DISPENSE_ROWS: tuple[Row, ...] = (
    ("DispL", r"[\On|\Off] ToPoint:robtarget [\ID:identno] Speed:speeddata [\T:num] Bead:beaddata Zone:zonedata Tool:tooldata [\WObj:wobjdata] [\Corr] [\TLoad:loaddata]", "move linear process"),
    ("DispC", r"[\On|\Off] CirPoint:robtarget ToPoint:robtarget [\ID:identno] Speed:speeddata [\T:num] Bead:beaddata Zone:zonedata Tool:tooldata [\WObj:wobjdata] [\Corr] [\TLoad:loaddata]", "move circular process"),
)  # fmt: skip

FORCE_ROWS: tuple[Row, ...] = (
    ("FCAct", r"Tool:tooldata [\WObj:wobjdata]", "setting"),
    ("FCDeact", r"", "setting"),
    ("FCCalib", r"Load:loaddata", "wait"),
    ("FCPressL", r"ToPoint:robtarget Speed:speeddata [\ForceChange:num] [\PosSupvDist:num] Force:num Zone:zonedata Tool:tooldata [\WObj:wobjdata] [\TLoad:loaddata]", "move linear process"),
    ("FCPressC", r"CirPoint:robtarget ToPoint:robtarget Speed:speeddata [\ForceChange:num] [\PosSupvDist:num] Force:num Zone:zonedata Tool:tooldata [\WObj:wobjdata] [\TLoad:loaddata]", "move circular process"),
    ("FCPress1LStart", r"ToPoint:robtarget Speed:speeddata Zone:zonedata Tool:tooldata [\WObj:wobjdata] [\TLoad:loaddata]", "move linear process"),
    ("FCPressEnd", r"ToPoint:robtarget Speed:speeddata Zone:zonedata Tool:tooldata [\WObj:wobjdata] [\TLoad:loaddata]", "move linear process"),
    ("FCRefStart", r"", "wait"),
    ("FCRefStop", r"", "none"),
    ("FCCondWaitWhile", r"", "wait"),
    ("FCSupvForce", r"", "none"),
    ("FCCondForce", r"", "none"),
)  # fmt: skip

FORCE_FUNCTIONS: tuple[Row, ...] = (
    ("FCGetForce", r"", "fcforcevector runtime"),
    ("FCIsForceMode", r"", "bool runtime"),
)  # fmt: skip

CONVEYOR_ROWS: tuple[Row, ...] = (
    ("WaitWObj", r"WObj:wobjdata [\RelDist:num] [\MaxTime:num] [\TimeFlag:bool&]", "wait"),
    ("DropWObj", r"WObj:wobjdata", "none"),
)  # fmt: skip

INDEPENDENT_ROWS: tuple[Row, ...] = (
    ("IndAMove", r"MecUnit:mecunit Axis:num [\ToAbsPos:robtarget|\ToAbsNum:num] Speed:num [\Ramp:num]", "move independent"),
    ("IndCMove", r"MecUnit:mecunit Axis:num Speed:num [\Ramp:num]", "move independent"),
    ("IndDMove", r"MecUnit:mecunit Axis:num Delta:num Speed:num [\Ramp:num]", "move independent"),
    ("IndRMove", r"MecUnit:mecunit Axis:num [\ToRelPos:robtarget|\ToRelNum:num] [\Short|\Fwd|\Bwd] Speed:num [\Ramp:num]", "move independent"),
    ("IndReset", r"MecUnit:mecunit Axis:num [\RefPos:robtarget|\RefNum:num] [\Short|\Fwd|\Bwd|\Old]", "setting"),
)  # fmt: skip

INDEPENDENT_FUNCTIONS: tuple[Row, ...] = (
    ("IndInpos", r"MecUnit:mecunit Axis:num", "bool runtime"),
    ("IndSpeed", r"MecUnit:mecunit Axis:num <\InSpeed|\ZeroSpeed>", "bool runtime"),
)  # fmt: skip

_ZONE = r"[\Inside|\Outside] Shape:shapedata&"
_WZ = r"<\Temp|\Stat> WorldZone:wztemporary/wzstationary&"
WORLDZONE_ROWS: tuple[Row, ...] = (
    ("WZBoxDef", rf"{_ZONE} LowPoint:pos HighPoint:pos", "none"),
    ("WZCylDef", rf"{_ZONE} CentrePoint:pos Radius:num Height:num", "none"),
    ("WZSphDef", rf"{_ZONE} CentrePoint:pos Radius:num", "none"),
    ("WZHomeJointDef", rf"{_ZONE} MiddleJointVal:jointtarget DeltaJointVal:jointtarget", "none"),
    ("WZLimJointDef", rf"{_ZONE} LowJointVal:jointtarget HighJointVal:jointtarget", "none"),
    ("WZDOSet", rf"{_WZ} [\Inside|\Before] Shape:shapedata Signal:signaldo SetValue:dionum", "none"),
    ("WZLimSup", rf"{_WZ} Shape:shapedata", "none"),
    ("WZEnable", r"WorldZone:wztemporary&", "none"),
    ("WZDisable", r"WorldZone:wztemporary&", "none"),
    ("WZFree", r"WorldZone:wztemporary&", "none"),
)  # fmt: skip

EGM_ROWS: tuple[Row, ...] = (
    ("EGMGetId", r"EGMid:egmident&", "none"),
    ("EGMReset", r"EGMid:egmident&", "none"),
    ("EGMSetupUC", r"MecUnit:mecunit EGMid:egmident& ExtConfig:string UCDevice:string <\Pose|\Joint|\PathCorr> [\CommTimeout:num]", "none"),
    ("EGMActJoint", r"EGMid:egmident [\Tool:tooldata] [\WObj:wobjdata] [\TLoad:loaddata] [\J1:egm_minmax] [\J2:egm_minmax] [\J3:egm_minmax] [\J4:egm_minmax] [\J5:egm_minmax] [\J6:egm_minmax] [\J7:egm_minmax] [\LpFilter:num] [\SampleRate:num] [\MaxPosDeviation:num] [\MaxSpeedDeviation:num]", "setting"),
    ("EGMActPose", r"EGMid:egmident [\StreamStart] [\Tool:tooldata] [\WObj:wobjdata] [\TLoad:loaddata] CorrFrame:pose CorrFrType:egmframetype SensorFrame:pose SensFrType:egmframetype [\x:egm_minmax] [\y:egm_minmax] [\z:egm_minmax] [\rx:egm_minmax] [\ry:egm_minmax] [\rz:egm_minmax] [\LpFilter:num] [\SampleRate:num] [\MaxPosDeviation:num] [\MaxSpeedDeviation:num]", "setting"),
    ("EGMRunJoint", r"EGMid:egmident Mode:egmstopmode [\NoWaitCond] [\J1] [\J2] [\J3] [\J4] [\J5] [\J6] [\J7] [\CondTime:num] [\RampInTime:num] [\RampOutTime:num] [\PosCorrGain:num]", "move guided"),
    ("EGMRunPose", r"EGMid:egmident Mode:egmstopmode [\NoWaitCond] [\x] [\y] [\z] [\rx] [\ry] [\rz] [\CondTime:num] [\RampInTime:num] [\RampOutTime:num] [\PosCorrGain:num]", "move guided"),
    ("EGMStop", r"EGMid:egmident Mode:egmstopmode [\RampOutTime:num]", "none"),
    ("EGMStreamStart", r"EGMid:egmident [\SampleRate:num]", "none"),
    ("EGMStreamStop", r"EGMid:egmident", "none"),
    ("EGMMoveL", r"EGMid:egmident ToPoint:robtarget Speed:speeddata Zone:zonedata Tool:tooldata [\WObj:wobjdata] [\TLoad:loaddata]", "move linear"),
    ("EGMMoveC", r"EGMid:egmident CirPoint:robtarget ToPoint:robtarget Speed:speeddata Zone:zonedata Tool:tooldata [\WObj:wobjdata] [\TLoad:loaddata]", "move circular"),
)  # fmt: skip

EGM_FUNCTIONS: tuple[Row, ...] = (
    ("EGMGetState", r"EGMid:egmident", "egmstate runtime"),
)  # fmt: skip

CSS_ROWS: tuple[Row, ...] = (
    ("CSSAct", r"", "setting"),
    ("CSSDeact", r"", "setting"),
)  # fmt: skip

OPTION_TYPES: tuple[tuple[str | None, str, tuple[Row, ...]], ...] = (
    (SOCKET, _SRC_SOCKET, (("socketdev", "atomic nonvalue"), ("socketstatus", "alias num"))),
    (RMQ, STD, (("rmqslot", "atomic nonvalue"), ("rmqmessage", "atomic nonvalue"), ("rmqheader", "record:", "partial"))),
    (VISION, _SRC_VISION, (
        ("cameradev", "atomic nonvalue"),
        ("cameratarget", "record: name string, cframe pose, val1 num, val2 num, val3 num, val4 num, val5 num, string1 string, string2 string, type num, cameraname string, sceneid num", "partial"),
    )),
    (ARC, _SRC_ARC, (("seamdata", "record:", "partial"), ("welddata", "record:", "partial"), ("weavedata", "record:", "partial"), ("trackdata", "record:", "partial"))),
    (DISPENSE, _SRC_DISPENSE, (("beaddata", "record:", "partial"),)),
    (WORLDZONES, STD, (("shapedata", "atomic nonvalue"), ("wztemporary", "record: wz num"), ("wzstationary", "record: wz num"))),
    (EGM, _SRC_EGM, (("egmident", "atomic nonvalue"), ("egmstopmode", "alias num"), ("egmframetype", "alias num"), ("egmstate", "alias num"), ("egm_minmax", "record: min num, max num"))),
    (FORCE, _SRC_FORCE, (("fcforcevector", "record: xforce num, yforce num, zforce num, xtorque num, ytorque num, ztorque num"),)),
)  # fmt: skip

BLOCKS: tuple[Block, ...] = (
    ("instruction", MULTITASKING, _SRC_MT, MULTITASKING_ROWS),
    ("function", MULTITASKING, _SRC_MT, MULTITASKING_FUNCTIONS),
    ("instruction", SOCKET, _SRC_SOCKET, SOCKET_ROWS),
    ("function", SOCKET, _SRC_SOCKET, SOCKET_FUNCTIONS),
    ("instruction partial", RMQ, STD, RMQ_ROWS),
    ("instruction partial", VISION, _SRC_VISION, VISION_ROWS),
    ("function partial", VISION, _SRC_VISION, VISION_FUNCTIONS),
    ("instruction partial", GRIPPER, _SRC_GRIPPER, GRIPPER_ROWS),
    ("function partial", GRIPPER, _SRC_GRIPPER, GRIPPER_FUNCTIONS),
    ("instruction partial", ARC, _SRC_ARC, ARC_ROWS),
    ("instruction partial", DISPENSE, _SRC_DISPENSE, DISPENSE_ROWS),
    ("instruction partial", FORCE, _SRC_FORCE, FORCE_ROWS),
    ("function partial", FORCE, _SRC_FORCE, FORCE_FUNCTIONS),
    ("instruction", CONVEYOR, _SRC_CONVEYOR, CONVEYOR_ROWS),
    ("instruction partial", WORLDZONES, STD, WORLDZONE_ROWS),
    ("instruction partial", EGM, _SRC_EGM, EGM_ROWS),
    ("function partial", EGM, _SRC_EGM, EGM_FUNCTIONS),
    ("instruction partial", CSS, _SRC_CSS, CSS_ROWS),
    ("instruction", INDEPENDENT, STD, INDEPENDENT_ROWS),
    ("function", INDEPENDENT, STD, INDEPENDENT_FUNCTIONS),
    *(("type", option, source, rows) for option, source, rows in OPTION_TYPES),
)
