/PROG  TAPE
/ATTR
OWNER		= MNEDITOR;
COMMENT		= "tape laying";
PROG_SIZE	= 1234;
CREATE		= DATE 24-01-15  TIME 10:20:00;
MODIFIED	= DATE 24-01-15  TIME 10:20:00;
FILE_NAME	= ;
VERSION		= 0;
LINE_COUNT	= 15;
MEMORY_SIZE	= 1500;
PROTECT		= READ_WRITE;
TCD:  STACK_SIZE	= 0,
      TASK_PRIORITY	= 50,
      TIME_SLICE	= 0,
      BUSY_LAMP_OFF	= 0,
      ABORT_REQUEST	= 0,
      PAUSE_REQUEST	= 0;
DEFAULT_GROUP	= 1,*,*,*,*;
CONTROL_CODE	= 00000000 00000000;
/APPL
/MN
   1:  !tape laying: approach, lay, arc, retract ;
   2:  UFRAME_NUM=0 ;
   3:  UTOOL_NUM=1 ;
   4:  J P[1:HOME] 20% FINE    ;
   5:  J P[2:approach] 50% CNT50    ;
   6:  DO[1:head]=ON ;
   7:  L P[3] 200mm/sec FINE    ;
   8:  C P[4]    
    :  P[5] 200mm/sec CNT10    ;
   9:  WAIT   0.50(sec) ;
  10:  FOR R[1]=1 TO 2 ;
  11:  L P[5] 100mm/sec FINE    ;
  12:  ENDFOR ;
  13:  L PR[2] 100mm/sec FINE    ;
  14:  L P[3] 100mm/sec FINE Offset,PR[3]    ;
  15:  DO[1:head]=OFF ;
  16:  J P[1:HOME] 20% FINE    ;
/POS
P[1:"HOME"]{
   GP1:
	UF : 0, UT : 1,	
	J1=     0.000 deg,	J2=   -90.000 deg,	J3=    90.000 deg,
	J4=     0.000 deg,	J5=    90.000 deg,	J6=     0.000 deg
};
P[2:"approach"]{
   GP1:
	UF : 0, UT : 1,		CONFIG : 'N U T, 0, 0, 0',
	X =  2000.000  mm,	Y =  -720.000  mm,	Z =   600.000  mm,
	W =   180.000 deg,	P =      .000 deg,	R =   180.000 deg
};
P[3]{
   GP1:
	UF : 0, UT : 1,		CONFIG : 'N U T, 0, 0, 0',
	X =  2000.000  mm,	Y =  -720.000  mm,	Z =   500.000  mm,
	W =   180.000 deg,	P =     0.000 deg,	R =   180.000 deg
};
P[4]{
   GP1:
	UF : 0, UT : 1,		CONFIG : 'N U T, 0, 0, 0',
	X =  2050.000  mm,	Y =  -600.000  mm,	Z =   500.000  mm,
	W =   180.000 deg,	P =     0.000 deg,	R =   180.000 deg
};
P[5]{
   GP1:
	UF : 0, UT : 1,		CONFIG : 'N U T, 0, 0, 0',
	X =  2000.000  mm,	Y =  -480.000  mm,	Z =   500.000  mm,
	W =   180.000 deg,	P =     0.000 deg,	R =   180.000 deg
};
/END
